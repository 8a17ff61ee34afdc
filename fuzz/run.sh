#!/usr/bin/env bash
# Builds the readers' libFuzzer targets with clang (ASan + UBSan) and runs
# each for SECONDS (default 60) from the committed seed corpus in
# fuzz/corpus/. New inputs go to build-fuzz/corpus/ (the seeds are never
# changed); a crashing input is kept in build-fuzz/artifacts/ and the script
# fails. Every crash found becomes a test in tests/test_readers.cpp.
#   bash fuzz/run.sh [SECONDS]
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
# A fixed seed makes a CI run explore the same inputs each time (a finding is
# then reproducible, not a flaky red); set OBSGROUP_FUZZ_SEED=0 for a random one.
seed=${OBSGROUP_FUZZ_SEED:-1}
jobs=$(nproc)

CXX=clang++ cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DOBSGROUP_BUILD_FUZZERS=ON \
  -DOBSGROUP_BUILD_TESTS=OFF -DOBSGROUP_BUILD_EXAMPLES=OFF -DOBSGROUP_BUILD_CLI=OFF > /dev/null
cmake --build build-fuzz -j"$jobs" --target fuzz_carmen fuzz_pose_file fuzz_pcd fuzz_depth_png fuzz_sequence_text \
  fuzz_ros1_message fuzz_ros2_message > /dev/null

mkdir -p build-fuzz/artifacts
status=0
for target in carmen pose_file pcd depth_png sequence_text ros1_message ros2_message; do
  work=build-fuzz/corpus/$target
  mkdir -p "$work"
  log=build-fuzz/fuzz_$target.log
  if build-fuzz/fuzz/fuzz_$target "$work" "fuzz/corpus/$target" -max_total_time="$seconds" -timeout=10 \
      -rss_limit_mb=2048 -max_len=16384 -print_final_stats=1 -seed="$seed" \
      -artifact_prefix="build-fuzz/artifacts/$target-" > "$log" 2>&1; then
    runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo "?")
    echo "fuzz_$target: ${seconds} s, $runs inputs, seed $seed, no crash"
  else
    echo "fuzz_$target: CRASH (see $log and build-fuzz/artifacts/)"
    grep -E "ERROR|SUMMARY|runtime error|terminate|abort" "$log" | head -5
    status=1
  fi
done
exit $status
