#!/usr/bin/env bash
# Builds obsgroup with AddressSanitizer + UndefinedBehaviorSanitizer
# (-DOBSGROUP_SANITIZE=ON, in build-asan/) and runs the whole test suite.
# Any report fails the run: UBSan does not recover, ASan stops at the first
# error, LeakSanitizer reports leaks at exit.
set -euo pipefail
cd "$(dirname "$0")/.."
# -O1 -g1: a quicker build than -O2 -g, line numbers in reports, asserts on.
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" \
  -DOBSGROUP_SANITIZE=ON > /dev/null
cmake --build build-asan -j"$(nproc)" > /dev/null
# alloc_dealloc_mismatch=0: Debian's PCL is built as C++14, where PointCloud
# has Eigen's class operator new (malloc); in C++17 code Eigen leaves it to
# aligned global new, so a cloud PCL allocates may be deleted by our code
# with global operator delete. glibc frees both alike; ASan would report it.
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:alloc_dealloc_mismatch=0:strict_string_checks=1:detect_stack_use_after_return=1}
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$PWD/scripts/lsan.supp:print_suppressions=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
ctest --test-dir build-asan --output-on-failure -j"$(nproc)" --timeout 600
