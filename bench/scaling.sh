#!/usr/bin/env bash
# The scaling benchmark: generates long buildings with the project's scan
# simulator, runs `obsgroup partition` on each with each sensed-space model
# (points = --paper, free-space, visibility = the default) and prints a markdown
# table: N, pairs evaluated, the overlap stage's rate (points model: in point
# queries of a per-observation search, bench/count_point_queries; all models:
# in the tests it makes itself), seconds per stage, peak RSS, groups, and the
# growth exponent of wall time from 10k to 100k scans per model. When MRPT's
# driver and the shared scaling inputs are available (../shared/peer/mrpt,
# ../shared/data/scaling, Debian package libmrpt-dev), it also times MRPT on
# the same inputs in the same run and prints the ratio.
#
#   bench/scaling.sh [--quick] [--output docs/performance.md]
#
# --quick runs 1k and 10k only. Each obsgroup case runs OBSGROUP_BENCH_RUNS
# times (default 5) and the median run is reported; MRPT runs once.
# Needs /usr/bin/time (Debian package `time`).
# Inputs are generated under ${OBSGROUP_BENCH_DIR:-/tmp/obsgroup-bench} and reused.
set -euo pipefail
cd "$(dirname "$0")/.."
quick=0 output=""
while [ $# -gt 0 ]; do
  case $1 in
    --quick) quick=1 ;;
    --output) output=$2; shift ;;
    *) sed -n 2,18p "$0"; exit 2 ;;
  esac
  shift
done
work=${OBSGROUP_BENCH_DIR:-${TMPDIR:-/tmp}/obsgroup-bench}
mkdir -p "$work"
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DOBSGROUP_BUILD_BENCHMARKS=ON > /dev/null
cmake --build build -j"$(nproc)" --target obsgroup_cli make_scaling_input count_point_queries > /dev/null
# A copy of the command, so that a rebuild during the run does not mix two versions.
cp build/obsgroup "$work/obsgroup"
exe=$work/obsgroup
commit=$(git rev-parse --short HEAD 2>/dev/null || echo unknown)

runs=${OBSGROUP_BENCH_RUNS:-5}
# Each run writes a fresh folder, all removed at the end: a run into a folder
# just emptied (by rm or by --force replacing it) would time the file system.
# On ext4 without a journal, creating a file next to thousands deleted in the
# last minutes scans past each of them (docs/performance.md). Inodes count
# as recently freed for up to five minutes: a run of the script waits until
# the folders the last one deleted are that old.
if [ -f "$work/outputs_deleted_at" ]; then
  wait=$((360 - ($(date +%s) - $(stat -c %Y "$work/outputs_deleted_at"))))
  if [ "$wait" -gt 0 ]; then echo "waiting $wait s: the last run's folders were deleted recently" >&2; sleep "$wait"; fi
fi
outs=$work/outs_$$
mkdir -p "$outs"
trap 'rm -rf "$outs"; touch "$work/outputs_deleted_at"' EXIT

# The sensed-space models and the options that select them: points is the
# paper's method (--paper: eq. 16-18, mean split, Ncut threshold 1), free-space
# and visibility the region models (best-Ncut split, threshold 0.7; visibility
# is the command's default).
model_options() {  # model
  case $1 in
    points) echo --paper ;;
    free-space) echo --sso free-space ;;
    visibility) ;;
  esac
}

# Runs obsgroup $runs times on one input with one model; prints one table row:
# the run with the median wall time, and the range of wall times over the runs;
# writes that median to $work/median_$key. `voxel` is the --voxel given (the
# point queries are counted on the filtered points). The point queries are
# counted for the points model only: they are the unit of its reference rate,
# and the region models match cells, not points.
run() {  # key label model input voxel
  local key=$1 label=$2 model=$3 input=$4 voxel=$5
  local out
  local queries=-1
  [ "$model" = points ] && queries=$(build/bench/count_point_queries "$input" 0.1 "$voxel")
  # shellcheck disable=SC2046  # model_options is split into words on purpose
  for r in $(seq "$runs"); do
    # A folder of its own per run, removed after the table (see $outs).
    out=$outs/${key}_$r
    /usr/bin/time -v -o "$work/time_${key}_$r" "$exe" partition "$input" -o "$out" -q --no-pictures \
      --voxel "$voxel" $(model_options "$model")
    cp "$out/partition.json" "$work/partition_${key}_$r.json"
  done
  python3 - "$work" "$key" "$runs" "$queries" "$label" "$model" <<'PY'
import json, re, sys
work, key, runs, queries, label, model = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4]), sys.argv[5], sys.argv[6]
rows = []
for r in range(1, runs + 1):
    p = json.load(open(f"{work}/partition_{key}_{r}.json"))
    log = open(f"{work}/time_{key}_{r}").read()
    wall = re.search(r"Elapsed \(wall clock\) time.*: (.*)", log).group(1).split(":")
    wall = sum(float(x) * 60 ** i for i, x in enumerate(reversed(wall)))
    rss = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", log).group(1)) / 1024
    rows.append((wall, rss, p))
rows.sort(key=lambda row: row[0])
wall, rss, p = rows[len(rows) // 2]
open(f"{work}/median_{key}", "w").write(f"{wall}\n")
t, s = p["timing_s"], p["statistics"]
rate = f"{s['point_tests'] / t['overlap'] / 1e6:.0f}" if t["overlap"] > 0 else "–"
if queries >= 0:
    query_count = f"{queries / 1e6:,.0f}"
    query_rate = f"{queries / t['overlap'] / 1e6:.0f}" if t["overlap"] > 0 else "–"
else:
    query_count = query_rate = "–"
spread = f" ({rows[0][0]:.2f}-{rows[-1][0]:.2f})" if runs > 1 else ""
print(f"| {label} | {model} | {p['observations']:,} | {s['points']:,} | {s['pairs_evaluated']:,} | {query_count} | "
      f"{query_rate} | {rate} | "
      f"{t['load']:.2f} | {t['overlap']:.2f} | {t['graph']:.2f} | {t['partition']:.2f} | {t['local_maps']:.2f} | "
      f"{t['outputs']:.2f} | {wall:.2f}{spread} | {max(row[1] for row in rows):,.0f} | {s['groups']:,} |")
PY
}

models="points free-space visibility"
sizes="1000 10000 100000"
[ $quick = 1 ] && sizes="1000 10000"
{
  echo "Machine: $(nproc) cores, $(awk '/MemTotal/{printf "%.0f GiB", $2/1048576}' /proc/meminfo), $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'); $(date -u +%Y-%m-%d); commit $commit."
  echo
  echo "| input | model | N | points | pairs evaluated | M point queries | overlap M queries/s | overlap M tests/s | load s | overlap s | graph s | partition s | local maps s | outputs s | wall s, median of $runs (range) | peak RSS MiB, max | groups |"
  echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
  for n in $sizes; do
    [ -f "$work/building_$n.clf" ] || build/bench/make_scaling_input 2d "$n" "$work/building_$n.clf" > /dev/null
    for model in $models; do
      run "2d_${n}_$model" "2D building, $n scans" "$model" "$work/building_$n.clf" 0
    done
  done
  [ -d "$work/depth_1000" ] || build/bench/make_scaling_input 3d 1000 "$work/depth_1000" > /dev/null
  for model in $models; do
    run "3d_1000_$model" "3D depth camera, 1000 x 19,200 points, voxel 5 cm" "$model" "$work/depth_1000" 0.05
  done
  if [ $quick = 0 ]; then
    echo
    printf "Growth of the median wall time from 10k to 100k 2D scans, log₁₀(t₁₀₀ₖ / t₁₀ₖ):"
    sep=" "
    for model in $models; do
      awk -v m="$model" -v s="$sep" -v a="$(cat "$work/median_2d_10000_$model")" -v b="$(cat "$work/median_2d_100000_$model")" \
        'BEGIN{printf "%s%s %.2f", s, m, log(b/a)/log(10)}'
      sep=", "
    done
    echo "."
  fi

  shared=../shared
  if [ -d "$shared/data/scaling" ] && [ -x "$shared/peer/mrpt/time_mrpt.sh" ] && [ -d /usr/include/mrpt ]; then
    echo
    echo "Side by side with MRPT's map-partition class on the same inputs, obsgroup's points model with MRPT's settings (delta 0.2 m, mean split, Ncut threshold 0.9):"
    echo
    echo "| input | N | obsgroup wall s (median of $runs) | obsgroup groups | MRPT wall s | MRPT groups | MRPT / obsgroup |"
    echo "|---|---|---|---|---|---|---|"
    for name in tile_sep_0600 tile_ovl_0300 tile_sep_1200 tile_sep_2400 tile_ovl_2400; do
      dir=$shared/data/scaling/$name
      ours=$(for r in $(seq "$runs"); do
        /usr/bin/time -v -o "$work/time_$name" "$exe" partition "$dir/$name.clf" -o "$work/out_$name" --force -q \
          --no-pictures --sso points --split mean --delta 0.2 --ncut-threshold 0.9
        awk -F': ' '/Elapsed \(wall clock\)/{n=split($2,t,":"); s=0; for(i=1;i<=n;i++) s=s*60+t[i]; print s}' "$work/time_$name"
      done | sort -n | awk '{v[NR]=$1} END{print v[int((NR+1)/2)]}')
      groups=$(python3 -c "import json;print(len(json.load(open('$work/out_$name/partition.json'))['groups']))")
      # MRPT at 2400 scans runs for many minutes (peer/mrpt/README.md: not finished after 319 s):
      # it is stopped at 120 s here, and the ratio is then a lower bound.
      limit=120
      mrpt=$(timeout $limit "$shared/peer/mrpt/time_mrpt.sh" -r 1 "$dir/$name.simplemap.gz" 2>/dev/null | tail -1 || true)
      if [ -n "$mrpt" ] && [ "$(echo "$mrpt" | awk '{print $1}')" = "$name" ]; then
        mwall=$(echo "$mrpt" | awk '{print $4}'); mgroups=$(echo "$mrpt" | awk '{print $3}')
        ratio=$(awk -v a="$mwall" -v b="$ours" 'BEGIN{printf "%.0f", a/b}')
      else
        mwall="stopped at ${limit} s"; mgroups="-"; ratio="> $(awk -v a=$limit -v b="$ours" 'BEGIN{printf "%.0f", a/b}')"
      fi
      n=${name##*_}; echo "| $name | $((10#$n)) | $ours | $groups | $mwall | $mgroups | $ratio |"
    done
    # The input of the reference rate (300 heavily overlapping real scans, "19.6 M point queries").
    ovl=$shared/data/scaling/tile_ovl_0300/tile_ovl_0300.clf
    queries=$(build/bench/count_point_queries "$ovl" 0.1 0)
    for r in $(seq "$runs"); do
      "$exe" partition "$ovl" -o "$work/out_ovl_rate" --force -q --no-pictures --paper
      python3 -c "import json;print(json.load(open('$work/out_ovl_rate/partition.json'))['timing_s']['overlap'])"
    done | sort -n | awk -v q="$queries" '{v[NR]=$1} END{m=v[int((NR+1)/2)];
      printf "\nThe overlap stage on tile_ovl_0300 (delta 0.1 m, %.1f M point queries): %.3f s, %.0f M point queries/s (median of %d runs; fastest %.3f s).\n", q/1e6, m, q/m/1e6, NR, v[1]}'
  fi
} | tee "$work/table.md"
if [ -n "$output" ]; then
  python3 - "$output" "$work/table.md" <<'PY'
import sys
path, table = sys.argv[1], open(sys.argv[2]).read()
text = open(path).read()
b, e = "<!-- generated:begin -->\n", "<!-- generated:end -->"
i, j = text.index(b) + len(b), text.index(e)
open(path, "w").write(text[:i] + table + text[j:])
print("updated", path)
PY
fi
