#!/usr/bin/env bash
# Builds obsgroup in Release (tests, examples and the Python module included)
# and runs the whole test suite: GoogleTest and pytest.
set -euo pipefail
cd "$(dirname "$0")/.."
# The Python module is built for the first python3 that has numpy and pytest
# (Debian's python3-numpy and python3-pytest); without one it is left out.
python_options=(-DOBSGROUP_BUILD_PYTHON=OFF)
for candidate in python3 /usr/bin/python3; do
  if command -v "$candidate" > /dev/null && "$candidate" -c "import numpy, pytest" 2> /dev/null; then
    python_options=(-DOBSGROUP_BUILD_PYTHON=ON "-DPython_EXECUTABLE=$(command -v "$candidate")")
    break
  fi
done
if [ "${python_options[0]}" = -DOBSGROUP_BUILD_PYTHON=OFF ]; then
  echo "test.sh: no python3 with numpy and pytest: the Python module is not built or tested" >&2
fi
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DOBSGROUP_BUILD_TESTS=ON -DOBSGROUP_BUILD_EXAMPLES=ON "${python_options[@]}"
cmake --build build -j"$(nproc)"
ctest --test-dir build --output-on-failure -j"$(nproc)"
