#!/usr/bin/env bash
# The pictures' cost: `obsgroup partition` with the default settings on the
# 10,010-scan log of the long 2D building (bench/make_scaling_input) and on
# the shipped real office log, with pictures and with --no-pictures. Medians
# of REPEATS runs of timing_s.pictures (map.png/.svg, weights.png,
# fiedler.png and a picture per local map) and of the whole run's wall time.
# Target: the pictures of 10,010 scans in at most 1 s, a default run of them
# under 4 s.
#
#   bench/pictures.sh [--output docs/performance.md] [REPEATS=5]
#
# With --output the table replaces the lines between "<!-- pictures:begin -->"
# and "<!-- pictures:end -->" of that file.
set -euo pipefail
cd "$(dirname "$0")/.."
output=""
if [ "${1:-}" = --output ]; then output=$2; shift 2; fi
repeats=${1:-5}
work=${OBSGROUP_BENCH_DIR:-${TMPDIR:-/tmp}/obsgroup-bench}
mkdir -p "$work"
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DOBSGROUP_BUILD_BENCHMARKS=ON > /dev/null
cmake --build build -j"$(nproc)" --target obsgroup_cli make_scaling_input > /dev/null
cp build/obsgroup "$work/obsgroup-pictures"  # a rebuild during the run cannot mix two versions
log=$work/building_10010.clf
[ -f "$log" ] || build/bench/make_scaling_input 2d 10010 "$log" > /dev/null
table=$(python3 - "$work" "$repeats" "$log" data/real/localization_demo/localization_demo.clf <<'PY'
import json, os, statistics, subprocess, sys, time
work, repeats, inputs = sys.argv[1], int(sys.argv[2]), sys.argv[3:]
exe = os.path.join(work, "obsgroup-pictures")
print(f"Medians of {repeats} runs, 2 cores, default settings.")
print()
print("| input | observations | groups | local-map pictures | pictures s | run with pictures s | run with --no-pictures s |")
print("|---|---|---|---|---|---|---|")
for log in inputs:
    pictures, with_pictures, without = [], [], []
    out = os.path.join(work, "pictures_out")
    for _ in range(repeats):
        start = time.perf_counter()
        subprocess.run([exe, "partition", log, "-o", out, "-q", "--force"], check=True)
        with_pictures.append(time.perf_counter() - start)
        run = json.load(open(os.path.join(out, "partition.json")))
        pictures.append(run["timing_s"]["pictures"])
        start = time.perf_counter()
        subprocess.run([exe, "partition", log, "-o", out + "_none", "-q", "--force", "--no-pictures"], check=True)
        without.append(time.perf_counter() - start)
    n = run["observations"]
    g = len(run["groups"])
    pngs = len([f for f in os.listdir(os.path.join(out, "local_maps")) if f.endswith(".png")])
    m = statistics.median
    print(f"| {os.path.basename(log)} | {n:,} | {g} | {pngs} | {m(pictures):.2f} | {m(with_pictures):.2f} | {m(without):.2f} |")
PY
)
echo "$table"
if [ -n "$output" ]; then
  printf '%s\n' "$table" > "$work/pictures_table.md"
  python3 bench/replace_section.py "$output" pictures "$work/pictures_table.md"
fi
