#!/usr/bin/env bash
# The refinement benchmark: `obsgroup partition --refine icp|lum` on 10,000
# simulated 2D scans of a long building (the scaling input of 10k), with the
# default grouping, three runs each. Prints a markdown table of the local-map
# stage (where refinement runs) and the whole run: median seconds and peak RSS.
# The target: refinement of 10,000 2D scans in at most 30 s on 2 cores.
#
#   bench/refinement.sh [--output docs/performance.md] [N]   (N scans, default 10000)
#
# With --output the table replaces the lines between "<!-- refinement:begin -->"
# and "<!-- refinement:end -->" of that file.
# Needs /usr/bin/time (Debian package `time`). Inputs are generated under
# ${OBSGROUP_BENCH_DIR:-/tmp/obsgroup-bench} and reused.
set -euo pipefail
cd "$(dirname "$0")/.."
output=""
if [ "${1:-}" = --output ]; then output=$2; shift 2; fi
n=${1:-10000}
work=${OBSGROUP_BENCH_DIR:-${TMPDIR:-/tmp}/obsgroup-bench}
mkdir -p "$work"
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DOBSGROUP_BUILD_BENCHMARKS=ON > /dev/null
cmake --build build -j"$(nproc)" --target obsgroup_cli make_scaling_input > /dev/null
cp build/obsgroup "$work/obsgroup-refine"  # a rebuild during the run cannot mix two versions
input=$work/scaling_2d_$n.clf
[ -f "$input" ] || build/bench/make_scaling_input 2d "$n" "$input" > /dev/null
table=$(mktemp)
{
echo "Machine: $(nproc) cores; $(date -u +%Y-%m-%d); commit $(git rev-parse --short HEAD 2>/dev/null || echo unknown)."
echo
echo "| refinement | N | groups | members moved | local maps s, median of 3 | whole run s, median of 3 | peak RSS MiB |"
echo "|---|---|---|---|---|---|---|"
for refine in none icp lum; do
  for r in 1 2 3; do
    /usr/bin/time -f "%e %M" -o "$work/refine_$refine.$r.time" "$work/obsgroup-refine" partition "$input" -q \
      --no-pictures --force --refine "$refine" -o "$work/refine_$refine.$r" 2> /dev/null
  done
  python3 - "$work" "$refine" "$n" <<'PY'
import json, statistics, sys
work, refine, n = sys.argv[1], sys.argv[2], int(sys.argv[3])
maps, walls, rss = [], [], []
for r in (1, 2, 3):
    p = json.load(open(f"{work}/refine_{refine}.{r}/partition.json"))
    wall, kib = open(f"{work}/refine_{refine}.{r}.time").read().split()[-2:]
    maps.append(p["timing_s"]["local_maps"]); walls.append(float(wall)); rss.append(int(kib) / 1024)
s = p["statistics"]
print(f"| {refine} | {n:,} | {s['groups']:,} | {s.get('refinement', {}).get('moved', 0):,} | {statistics.median(maps):.2f} | "
      f"{statistics.median(walls):.2f} | {max(rss):,.0f} |")
PY
done
} > "$table"
if [ -z "$output" ]; then
  cat "$table"
else
  python3 bench/replace_section.py "$output" refinement "$table"
fi
rm -f "$table"
