#!/usr/bin/env bash
# The dense-recordings benchmark: `obsgroup partition` with the default
# settings on a long simulated depth recording (640 x 480, one furnished room
# circled, 211 frames a turn) and a simulated lidar drive (64 beams, 120,000
# a sweep, through the long building), against the same command keeping every
# point (--voxel 0, what every run did before dense frames were reduced as
# they are read) on shorter pieces of both. Prints a markdown table: frames,
# points kept, groups, seconds (load and whole run) and peak RSS; then the
# rooms found on the simulated buildings with every point and with the default
# reduction (examples/evaluate_grouping --voxel 0|0.05: a 320 x 240 depth
# camera on every building, a 64-beam lidar on three), exact and drifted poses.
# The target: 2,110 depth frames in at most 90 s and 4 GiB, one or two places.
#
#   bench/dense.sh [--output docs/performance.md] [DEPTH_FRAMES LIDAR_SWEEPS]   (default 3000 1000)
#
# With --output the tables replace the lines between "<!-- dense:begin -->"
# and "<!-- dense:end -->", and "<!-- dense-rooms:begin -->" and
# "<!-- dense-rooms:end -->", of that file.
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
cmake -S . -B build -DOBSGROUP_BUILD_EXAMPLES=ON > /dev/null
cmake --build build -j"$(nproc)" --target obsgroup_cli make_scaling_input evaluate_grouping > /dev/null
cp build/obsgroup "$work/obsgroup-dense"  # a rebuild during the run cannot mix two versions
input() {  # kind count
  local folder=$work/dense_$1_$2
  [ -d "$folder" ] || build/bench/make_scaling_input "$1" "$2" "$folder" > /dev/null
  echo "$folder"
}
run() {  # label folder [options...]
  local label=$1 folder=$2 key
  shift 2
  key=$(basename "$folder")$(printf '%s' "$*" | tr -c 'a-z0-9.' '_')
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
echo "| input | frames | frame voxel m | frames reduced | points kept (grouped) | groups | load s | whole run s | peak RSS GiB |"
echo "|---|---|---|---|---|---|---|---|---|"
run "depth 640x480, one room, default" "$depth"
run "depth 640x480, one room, default" "$depth_short"
run "depth 640x480, one room, --voxel 0 (every point)" "$depth_short" --voxel 0
run "depth 640x480, one room, --keyframes 0.1,10" "$depth" --keyframes 0.1,10
run "lidar 64 x 1875, long building, default" "$lidar"
run "lidar 64 x 1875, long building, default" "$lidar_short"
run "lidar 64 x 1875, long building, --voxel 0 (every point)" "$lidar_short" --voxel 0
} > "$table"
rooms=$(mktemp)
{
echo "| sensor | buildings | rooms found, every point | rooms found, 0.05 m | rooms whole | rooms pure | grouping s, every point | grouping s, 0.05 m |"
echo "|---|---|---|---|---|---|---|---|"
for sensor in depth lidar; do
  if [ $sensor = depth ]; then selection="--sensors depth --depth-size 320x240"; label="depth camera 320 x 240"
  else selection="--sensors lidar --datasets office,loop,rooms20"; label="64-beam lidar"; fi
  for voxel in 0 0.05; do
    # shellcheck disable=SC2086
    build/examples/evaluate_grouping --model visibility $selection --voxel $voxel | grep '^summary' > "$work/rooms_${sensor}_$voxel.txt"
  done
  python3 - "$work" "$sensor" "$label" <<'PY'
import re, sys
work, sensor, label = sys.argv[1:4]
def parse(voxel):
    line = open(f"{work}/rooms_{sensor}_{voxel}.txt").read()
    whole = re.search(r"rooms whole (\d+)/(\d+)", line)
    found = re.search(r"found (\d+)", line).group(1)
    pure = re.search(r"pure (\d+)", line).group(1)
    seconds = re.search(r"\)\s+([\d.]+) s\s*$", line).group(1)
    return whole.group(1), whole.group(2), found, pure, seconds
a, b = parse("0"), parse("0.05")
buildings = "office, loop, 20 rooms" if sensor == "lidar" else "all five"
print(f"| {label} | {buildings} | {a[2]} of {a[1]} | {b[2]} of {b[1]} | {a[0]} / {b[0]} | {a[3]} / {b[3]} | {a[4]} | {b[4]} |")
PY
done
} > "$rooms"
if [ -z "$output" ]; then
  cat "$table" "$rooms"
else
  python3 bench/replace_section.py "$output" dense "$table"
  python3 bench/replace_section.py "$output" dense-rooms "$rooms"
fi
rm -f "$table" "$rooms"
