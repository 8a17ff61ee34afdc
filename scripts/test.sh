#!/usr/bin/env bash
# Builds obsgroup in Release (tests, examples and the Python module included)
# and runs the whole test suite: GoogleTest and pytest.
set -euo pipefail
cd "$(dirname "$0")/.."
# The Python module is built for Debian's python3 with numpy and pytest;
# without one it is left out.
python=$(bash scripts/find-python.sh)
if [ -n "$python" ]; then
  python_options=(-DOBSGROUP_BUILD_PYTHON=ON "-DPython_EXECUTABLE=$python")
else
  python_options=(-DOBSGROUP_BUILD_PYTHON=OFF)
  echo "test.sh: no python3 with numpy and pytest: the Python module is not built or tested" >&2
fi
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DOBSGROUP_BUILD_TESTS=ON -DOBSGROUP_BUILD_EXAMPLES=ON "${python_options[@]}"
cmake --build build -j"$(nproc)"
ctest --test-dir build --output-on-failure -j"$(nproc)"
