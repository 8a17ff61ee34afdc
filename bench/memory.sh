#!/usr/bin/env bash
# Where a grouping's bytes and seconds go at scale: bench/memory_breakdown on
# the 100,100-scan log of the long 2D building (bench/make_scaling_input), then
# `obsgroup partition --no-pictures` with the default settings on 10,010 and
# 100,100 scans: wall time, peak resident memory and the stages' timing_s
# (medians of REPEATS runs). Targets of the scale work: 100,000 scans in at
# most 20 s and 1.6 GiB; 1,000,000 in at most 10 minutes and 16 GiB.
#
#   bench/memory.sh [--output docs/performance.md] [--million] [REPEATS=3]
#
# --million adds one run of 1,001,000 scans (a 2.3 GB log made once in the
# work folder; about 6 minutes and 16 GiB on 2 cores).
#
# With --output the tables replace the lines between "<!-- memory:begin -->"
# and "<!-- memory:end -->" of that file.
set -euo pipefail
cd "$(dirname "$0")/.."
output="" sizes="10010 100100"
while [ $# -gt 0 ]; do
  case $1 in
    --output) output=$2; shift 2 ;;
    --million) sizes="$sizes 1001000"; shift ;;
    *) break ;;
  esac
done
repeats=${1:-3}
work=${OBSGROUP_BENCH_DIR:-${TMPDIR:-/tmp}/obsgroup-bench}
mkdir -p "$work"
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DOBSGROUP_BUILD_BENCHMARKS=ON > /dev/null
cmake --build build -j"$(nproc)" --target obsgroup_cli make_scaling_input memory_breakdown > /dev/null
cp build/obsgroup "$work/obsgroup-memory"  # a rebuild during the run cannot mix two versions
for n in $sizes; do
  [ -f "$work/building_$n.clf" ] || build/bench/make_scaling_input 2d "$n" "$work/building_$n.clf" > /dev/null
done
table=$(mktemp)
{
echo "Machine: $(nproc) cores, $(awk '/MemTotal/ {printf "%.0f GiB", $2 / 1048576}' /proc/meminfo); $(date -u +%Y-%m-%d); commit $(git rev-parse --short HEAD 2>/dev/null || echo unknown)."
echo
echo "Bytes of each structure, 100,100 scans of the 2D building, default settings (\`bench/memory_breakdown\`):"
echo
build/bench/memory_breakdown "$work/building_100100.clf" |
  sed -e 's/^observations\(.*\)/Observations\1.\n/' -e 's/^peak resident memory\(.*\)/\nPeak resident memory of memory_breakdown\1./'
echo
python3 - "$work" "$repeats" $sizes <<'PY'
import json, os, statistics, subprocess, sys, time
work, repeats, sizes = sys.argv[1], int(sys.argv[2]), [int(n) for n in sys.argv[3:]]
exe = os.path.join(work, "obsgroup-memory")
stages = ["load", "overlap", "graph", "partition", "local_maps", "places", "outputs"]
print(f"`obsgroup partition --no-pictures`, default settings, the run of median wall time of {repeats} (a million scans: one run; peak RSS: the largest of the runs; `outputs` includes `places`):")
print()
print("| scans | wall s | peak RSS MiB, max | " + " | ".join(f"{s} s" for s in stages) + " | groups |")
print("|---" * (len(stages) + 4) + "|")
# Every run writes a folder of its own, all removed after the table: a run
# into a folder just emptied would time the file system, not obsgroup. On
# ext4 without a journal, creating a file next to thousands deleted in the
# last minutes scans past each of them (docs/performance.md): the 5,004
# files of a 100,100-scan run then took 3 s more. Inodes count as recently
# freed for up to five minutes, so a run of the script waits until the
# folders the last one deleted are that old.
stamp = os.path.join(work, "outputs_deleted_at")
if os.path.exists(stamp):
    wait = 360 - (time.time() - os.path.getmtime(stamp))
    if wait > 0:
        print(f"waiting {wait:.0f} s: the last run's folders were deleted {360 - wait:.0f} s ago", file=sys.stderr)
        time.sleep(wait)
outs = os.path.join(work, f"memory_outs_{os.getpid()}")
os.makedirs(outs)
for n in sizes:
    runs = []
    for r in range(repeats if n < 1000000 else 1):
        out = os.path.join(outs, f"{n}_{r}")
        start = time.perf_counter()
        p = subprocess.Popen([exe, "partition", os.path.join(work, f"building_{n}.clf"), "--output", out, "-q", "--no-pictures"])
        _, status, usage = os.wait4(p.pid, 0)
        wall = time.perf_counter() - start
        if status != 0: sys.exit(f"obsgroup failed on {n} scans")
        d = json.load(open(os.path.join(out, "partition.json")))
        runs.append((wall, usage.ru_maxrss / 1024, d["timing_s"], len(d["groups"])))
    runs.sort(key=lambda r: r[0])
    wall, rss, t, groups = runs[len(runs) // 2]
    print(f"| {n:,} | {wall:.2f} | {max(r[1] for r in runs):,.0f} | " + " | ".join(f"{t[s]:.2f}" for s in stages) + f" | {groups:,} |")
subprocess.run(["rm", "-rf", outs], check=True)
open(stamp, "w").close()
PY
} > "$table"
if [ -z "$output" ]; then
  cat "$table"
else
  python3 bench/replace_section.py "$output" memory "$table"
fi
rm -f "$table"
