#!/usr/bin/env bash
# The dense-recordings benchmark: `obsgroup partition` with the default
# settings on a long simulated depth recording (640 x 480, one furnished room
# circled, 211 frames a turn) and a simulated lidar drive (64 beams, 120,000
# a sweep, through the long building), against the same command keeping every
# point (--voxel 0, what every run did before dense frames were reduced as
# they are read) on shorter pieces of both. Prints a markdown table: frames,
# points read, points kept, groups, seconds (load and whole run) and peak RSS.
# The target: 2,110 depth frames in at most 90 s and 4 GiB, one or two places.
#
#   bench/dense.sh [--output docs/performance.md] [DEPTH_FRAMES LIDAR_SWEEPS]   (default 3000 1000)
#
# With --output the table replaces the lines between "<!-- dense:begin -->"
# and "<!-- dense:end -->" of that file.
# Needs /usr/bin/time (Debian package `time`) and about 2.5 GB of disk for the
# inputs, generated under ${OBSGROUP_BENCH_DIR:-/tmp/obsgroup-bench} and reused.
set -euo pipefail
cd "$(dirname "$0")/.."
output=""
if [ "${1:-}" = --output ]; then output=$2; shift 2; fi
depth_frames=${1:-3000}
lidar_sweeps=${2:-1000}
work=${OBSGROUP_BENCH_DIR:-${TMPDIR:-/tmp}/obsgroup-bench}
mkdir -p "$work"
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DOBSGROUP_BUILD_BENCHMARKS=ON > /dev/null
cmake --build build -j"$(nproc)" --target obsgroup_cli make_scaling_input > /dev/null
cp build/obsgroup "$work/obsgroup-dense"  # a rebuild during the run cannot mix two versions
input() {  # kind count
  local folder=$work/dense_$1_$2
  [ -d "$folder" ] || build/bench/make_scaling_input "$1" "$2" "$folder" > /dev/null
  echo "$folder"
}
run() {  # label folder [options...]
  local label=$1 folder=$2 key
  shift 2
  key=$(basename "$folder")${1:+_voxel$2}
  /usr/bin/time -f "%e %M" -o "$work/$key.time" "$work/obsgroup-dense" partition "$folder" -q --force \
    -o "$work/$key.out" "$@" 2> "$work/$key.err" || { echo "| $label | failed: $(tail -1 "$work/$key.err") |"; return; }
  python3 - "$work" "$key" "$label" <<'PY'
import json, sys
work, key, label = sys.argv[1:4]
p = json.load(open(f"{work}/{key}.out/partition.json"))
wall, kib = open(f"{work}/{key}.time").read().split()[-2:]
s, t, q = p["statistics"], p["timing_s"], p["parameters"]
frames = sum(len(g) for g in p["groups"])
print(f"| {label} | {frames:,} | {q['frame_voxel'] if q['frames_reduced'] else 'none'} | {q['frames_reduced']:,} | "
      f"{s['points']:,} | {s['groups']} | {t['load']:.1f} | {float(wall):.1f} | {int(kib) / 1048576:.2f} |")
PY
}
depth=$(input depth "$depth_frames")
depth_short=$(input depth 211)
lidar=$(input lidar "$lidar_sweeps")
lidar_short=$(input lidar 100)
table=$(mktemp)
{
echo "Machine: $(nproc) cores; $(date -u +%Y-%m-%d); commit $(git rev-parse --short HEAD 2>/dev/null || echo unknown)."
echo
echo "| input | frames | frame voxel m | frames reduced | points kept | groups | load s | whole run s | peak RSS GiB |"
echo "|---|---|---|---|---|---|---|---|---|"
run "depth 640x480, one room, default" "$depth"
run "depth 640x480, one room, default" "$depth_short"
run "depth 640x480, one room, --voxel 0 (every point)" "$depth_short" --voxel 0
run "lidar 64 x 1875, long building, default" "$lidar"
run "lidar 64 x 1875, long building, default" "$lidar_short"
run "lidar 64 x 1875, long building, --voxel 0 (every point)" "$lidar_short" --voxel 0
} > "$table"
if [ -z "$output" ]; then
  cat "$table"
else
  python3 bench/replace_section.py "$output" dense "$table"
fi
rm -f "$table"
