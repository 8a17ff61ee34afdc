#!/usr/bin/env bash
# The Python module against the command, side by side on one machine: a
# 10,010-scan log of the long 2D building (bench/make_scaling_input) read by
# the C++ reader (time_log_read) and by obsgroup.read, and grouped by
# `obsgroup partition --no-pictures` and by obsgroup.read + Grouping().compute()
# in Python. Medians of REPEATS runs, each in a fresh process; prints a
# markdown table, and checks that both give the same groups.
# Targets: reading within 1.2x the C++ reader, reading plus grouping within
# 1.2x the command without pictures.
#
#   bench/python.sh [--output docs/performance.md] [SCANS=10010] [REPEATS=5]
#
# With --output the table replaces the lines between "<!-- python:begin -->"
# and "<!-- python:end -->" of that file. The module is the one the build
# folder holds (scripts/test.sh builds it).
set -euo pipefail
cd "$(dirname "$0")/.."
output=""
if [ "${1:-}" = --output ]; then output=$2; shift 2; fi
scans=${1:-10010}
repeats=${2:-5}
work=${OBSGROUP_BENCH_DIR:-${TMPDIR:-/tmp}/obsgroup-bench}
mkdir -p "$work"
python=$(bash scripts/find-python.sh)
[ -n "$python" ] || { echo "python.sh: needs a python3 with numpy and pytest" >&2; exit 1; }
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DOBSGROUP_BUILD_BENCHMARKS=ON -DOBSGROUP_BUILD_PYTHON=ON \
  "-DPython_EXECUTABLE=$python" > /dev/null
cmake --build build -j"$(nproc)" --target obsgroup_cli obsgroup_python make_scaling_input time_log_read > /dev/null
log=$work/building_$scans.clf
[ -f "$log" ] || build/bench/make_scaling_input 2d "$scans" "$log" > /dev/null
table=$(PYTHONPATH=build/python "$python" - "$log" "$repeats" "$work" <<'PY'
import json, os, statistics, subprocess, sys, time

log, repeats, work = sys.argv[1], int(sys.argv[2]), sys.argv[3]

def seconds(command):
    start = time.perf_counter()
    out = subprocess.run(command, check=True, capture_output=True, text=True).stdout
    return time.perf_counter() - start, out

python_read = ("import obsgroup, sys, time\n"
               "t = time.perf_counter(); s = obsgroup.read(sys.argv[1])\n"
               "print(time.perf_counter() - t, len(s))\n")
python_group = ("import json, obsgroup, sys, time\n"
                "t = time.perf_counter(); s = obsgroup.read(sys.argv[1]); g = obsgroup.Grouping(); g.extend(s)\n"
                "p = g.compute(); t = time.perf_counter() - t\n"
                "json.dump(p.groups, open(sys.argv[2], 'w')); print(t)\n")
rows = {k: [] for k in ("cpp_read", "cmd_load", "py_read", "command", "py_group")}
out = os.path.join(work, "python_bench_out")
groups_file = os.path.join(work, "python_bench_groups.json")
for _ in range(repeats):
    text = subprocess.run(["build/bench/time_log_read", log, "1"], check=True, capture_output=True, text=True).stdout
    rows["cpp_read"].append(float(text.rsplit(":", 1)[1].split()[0]))  # "LOG: N scans, best of 1: T s"
    text = subprocess.run([sys.executable, "-c", python_read, log], check=True, capture_output=True, text=True).stdout
    rows["py_read"].append(float(text.split()[0]))
    wall, _ = seconds(["build/obsgroup", "partition", log, "-o", out, "--force", "-q", "--no-pictures"])
    rows["command"].append(wall)
    rows["cmd_load"].append(json.load(open(os.path.join(out, "partition.json")))["timing_s"]["load"])
    start = time.perf_counter()
    subprocess.run([sys.executable, "-c", python_group, log, groups_file], check=True, capture_output=True)
    rows["py_group"].append(time.perf_counter() - start)
same = json.load(open(groups_file)) == json.load(open(os.path.join(out, "partition.json")))["groups"]
m = {k: statistics.median(v) for k, v in rows.items()}
n = int(subprocess.run(["grep", "-c", "^ROBOTLASER1", log], capture_output=True, text=True).stdout)
print(f"{n:,} scans of the 2D building, medians of {repeats} runs, 2 cores; each Python run is a fresh")
print("process (interpreter start and `import obsgroup` included in the grouping rows, as in the command's).")
print()
print("| what | C++ | Python | Python / C++ | target |")
print("|---|---|---|---|---|")
print(f"| read the log: the parser alone (`time_log_read`) / `obsgroup.read` | {m['cpp_read']:.3f} s | "
      f"{m['py_read']:.3f} s | {m['py_read'] / m['cpp_read']:.2f} | 1.2 |")
print(f"| read the log into clouds: the command's reading stage (`timing_s.load`) / `obsgroup.read` | "
      f"{m['cmd_load']:.3f} s | {m['py_read']:.3f} s | {m['py_read'] / m['cmd_load']:.2f} | 1.2 |")
print(f"| read and group (`partition --no-pictures` / `read` + `Grouping().compute()`) | {m['command']:.2f} s | "
      f"{m['py_group']:.2f} s | {m['py_group'] / m['command']:.2f} | 1.2 |")
print()
print(f"Same groups from both: {'yes' if same else 'NO'}. The command also builds the local maps, the "
      "topological map and the places and writes them; the Python rows do not. `obsgroup.read` does what "
      "the command's reading stage does (the log parsed, then a PCL cloud built per scan, which the numpy "
      "views show) and then wraps each observation for Python; the parser alone builds no cloud.")
PY
)
echo "$table"
if [ -n "$output" ]; then
  printf '%s\n' "$table" > "$work/python_table.md"
  "$python" bench/replace_section.py "$output" python "$work/python_table.md"
fi
