#!/usr/bin/env bash
# The online-grouping benchmark: bench/online_latency on the long building of
# the scaling input (2D laser of 360 beams; depth camera of 160 x 120
# points), generated in memory. Prints a markdown table of the latency of
# insert + update() per observation (median, 99th percentile, worst), what one
# update recomputes, and for full replays the replay time beside the batch
# compute() of the same observations. Every row checks that the online
# groups equal the batch's.
#
#   bench/online.sh [--output docs/performance.md] [--quick]
#
# --quick leaves out the full replays of 10k (the exact one takes about 11 minutes)
# and the 50k and 10k depth rows. With --output the table
# replaces the lines between "<!-- online:begin -->" and "<!-- online:end -->".
set -euo pipefail
cd "$(dirname "$0")/.."
output="" quick=0
while [ $# -gt 0 ]; do
  case $1 in
    --output) output=$2; shift ;;
    --quick) quick=1 ;;
    *) sed -n 2,14p "$0"; exit 2 ;;
  esac
  shift
done
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DOBSGROUP_BUILD_BENCHMARKS=ON > /dev/null
cmake --build build -j"$(nproc)" --target online_latency > /dev/null
exe=$(mktemp)
cp build/bench/online_latency "$exe" && chmod +x "$exe"  # a rebuild during the run cannot mix two versions
table=$(mktemp)
{
echo "Machine: $(nproc) cores; $(date -u +%Y-%m-%d); commit $(git rev-parse --short HEAD 2>/dev/null || echo unknown)."
echo
echo "| input | N | timed inserts | update every | exact every | median ms | p99 ms | worst ms | overlaps recomputed per update | split nodes solved per update | replay | batch compute() s | lowest ARI against batch | final groups equal batch |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
"$exe" 2d 1000
"$exe" 2d 1000 --exact-every 50 --check 50
"$exe" 2d 10000 --sample 200
"$exe" 2d 10000 --sample 200 --exact-every 100
"$exe" 2d 10000 --update-every 100
"$exe" 2d 10000 --update-every 1000
"$exe" 3d 1000
"$exe" 3d 1000 --exact-every 50 --check 50
if [ "$quick" = 0 ]; then
  "$exe" 2d 10000
  "$exe" 2d 10000 --exact-every 100 --check 1000
  "$exe" 2d 50000 --sample 20
  "$exe" 2d 50000 --sample 50 --exact-every 1000
  "$exe" 3d 10000 --sample 20
  "$exe" 3d 10000 --sample 50 --exact-every 1000
fi
} > "$table"
rm -f "$exe"
if [ -z "$output" ]; then
  cat "$table"
else
  python3 bench/replace_section.py "$output" online "$table"
fi
rm -f "$table"
