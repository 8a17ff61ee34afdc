#!/usr/bin/env bash
# Prints the first python3 that can build and test the Python module (it
# imports numpy and pytest: Debian's python3-numpy and python3-pytest), or
# nothing. A python3 of another installation may come first on PATH.
for candidate in python3 /usr/bin/python3; do
  if command -v "$candidate" > /dev/null && "$candidate" -c "import numpy, pytest" 2> /dev/null; then
    command -v "$candidate"
    exit 0
  fi
done
