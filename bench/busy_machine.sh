#!/usr/bin/env bash
# The command beside other work, as on a robot's computer: `obsgroup stream`
# of the 1,001-scan building and `obsgroup partition --no-pictures` of 10,010
# and 100,100 scans (bench/make_scaling_input 2d), default settings, on a
# quiet machine and beside one busy process (a shell loop that keeps one core
# busy), with the command's idle OpenMP threads sleeping (its default: it
# starts itself with OMP_WAIT_POLICY=passive) and spinning
# (OMP_WAIT_POLICY=active, as OpenMP's own default lets them). Prints a
# markdown table of the median wall time of REPEATS runs, and checks that every
# run wrote the same partition.json (timings aside).
#
#   bench/busy_machine.sh [--output docs/performance.md] [REPEATS]
#
# REPEATS: runs of each cell (3 when not given).
#
# With --output the table replaces the lines between "<!-- busy:begin -->"
# and "<!-- busy:end -->" of that file. About 15 minutes on 2 cores.
set -euo pipefail
cd "$(dirname "$0")/.."
output=""
while [ $# -gt 0 ]; do
  case $1 in
    --output) output=$2; shift 2 ;;
    -h|--help) sed -n 2,17p "$0"; exit 0 ;;
    *) break ;;
  esac
done
repeats=${1:-3}
work=${OBSGROUP_BENCH_DIR:-${TMPDIR:-/tmp}/obsgroup-bench}
mkdir -p "$work"
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DOBSGROUP_BUILD_BENCHMARKS=ON > /dev/null
cmake --build build -j"$(nproc)" --target obsgroup_cli make_scaling_input > /dev/null
cp build/obsgroup "$work/obsgroup-busy"  # a rebuild during the run cannot mix two versions
for n in 1001 10010 100100; do
  [ -f "$work/building_$n.clf" ] || build/bench/make_scaling_input 2d "$n" "$work/building_$n.clf" > /dev/null
done
table=$(mktemp)
trap 'rm -f "$table"' EXIT
{
echo "Machine: $(nproc) cores; $(date -u +%Y-%m-%d); commit $(git describe --always --dirty 2>/dev/null || echo unknown)."
echo
python3 - "$work" "$repeats" <<'PY'
import json, os, signal, statistics, subprocess, sys, time
work, repeats = sys.argv[1], int(sys.argv[2])
exe = os.path.join(work, "obsgroup-busy")
jobs = [("stream, 1,001 scans", ["stream", os.path.join(work, "building_1001.clf")]),
        ("partition, 10,010 scans", ["partition", os.path.join(work, "building_10010.clf")]),
        ("partition, 100,100 scans", ["partition", os.path.join(work, "building_100100.clf")])]
policies = [("sleeping (the command's default)", None), ("spinning (OMP_WAIT_POLICY=active)", "active")]
print(f"Wall seconds, the median of {repeats} runs (`-q --no-pictures`, default settings):")
print()
print("| run | idle threads | quiet machine | beside one busy process |")
print("|---|---|---|---|")
for label, words in jobs:
    reference = None
    for policy_label, policy in policies:
        env = dict(os.environ)
        env.pop("OMP_WAIT_POLICY", None)
        if policy: env["OMP_WAIT_POLICY"] = policy
        cells = []
        for busy in (False, True):
            loop = subprocess.Popen(["sh", "-c", "while :; do :; done"]) if busy else None
            try:
                walls = []
                for _ in range(repeats):
                    out = os.path.join(work, "busy_out")
                    subprocess.run(["rm", "-rf", out], check=True)
                    start = time.perf_counter()
                    subprocess.run([exe, *words, "--output", out, "-q", "--no-pictures"], env=env, check=True,
                                   stdout=subprocess.DEVNULL)
                    walls.append(time.perf_counter() - start)
                    d = json.load(open(os.path.join(out, "partition.json")))
                    d.pop("timing_s", None)
                    if reference is None: reference = d
                    elif d != reference: sys.exit(f"{label}: the partition differs with {policy_label}")
            finally:
                if loop:
                    loop.send_signal(signal.SIGKILL)
                    loop.wait()
            cells.append(f"{statistics.median(walls):.2f}")
        print(f"| {label} | {policy_label} | " + " | ".join(cells) + " |")
PY
} > "$table"
if [ -z "$output" ]; then
  cat "$table"
else
  python3 bench/replace_section.py "$output" busy "$table"
fi
