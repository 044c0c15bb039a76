#!/usr/bin/env bash
# Benchmark (not a test): a large synthetic city street painted in shards through a one-node
# Slurm cluster (one_node_cluster.sh, as root), side by side with the one-process run.
#
#   bash tests/slurm/city_block_bench.sh WORK [FRAMES_PER_STREAM [SHARDS]]
#
# Makes WORK/capture with `fresco synth` (a 160 m street of 32 buildings, its mesh subdivided
# to 2.09 M triangles; 8 streams at 1280x720: 4 walkers along the pavements and 4 cameras on
# masts; FRAMES_PER_STREAM each, default 300), paints it once in one process (WORK/whole) and
# once as Slurm jobs (WORK/job: the pre-pass job, an array of SHARDS shards, default 16, the
# merge), every process niced and timed with /usr/bin/time. The array runs with --exclusive:
# one shard at a time has the node, as each would have its own node on a cluster of SHARDS
# nodes; so the makespan there is projected as the pre-pass job's time + the slowest
# shard's + the merge's, each measured here (in wall time, and in CPU time, which the
# machine's other load sways less). Prints the figures (also in WORK/figures.txt),
# compares the merged outputs with the one-process run's (byte for byte, then the largest
# difference of any atlas page's texel with ImageMagick's `compare`), stops the daemons it
# started and removes the generated data (KEEP=1 keeps it). FRESCO: the binary (default
# build/app/fresco).
set -euo pipefail
[ $# -ge 1 ] || { echo "usage: $0 WORK [FRAMES_PER_STREAM [SHARDS]]" >&2; exit 2; }
here=$(cd "$(dirname "$0")" && pwd)
fresco=$(realpath "${FRESCO:-build/app/fresco}")
mkdir -p "$1"
work=$(realpath "$1")
frames=${2:-300}
shards=${3:-16}
# The decisions that couple the charts, taken by hand (docs/guide/slurm.md).
sets=(--set pipeline.update=quality --set pipeline.refine.mode=off
      --set pipeline.refine.joint=false --set pipeline.background.mode=off)

cleanup() {
  bash "$here/one_node_cluster.sh" stop "$work/cluster" >/dev/null 2>&1 || true
  [ "${KEEP:-0}" = 1 ] || rm -rf "$work/capture" "$work/whole" "$work/job" "$work/cluster"
}
trap cleanup EXIT

cat > "$work/city.json" <<'SPEC'
{"scene": {"builtin": "street", "length_m": 160, "street_width_m": 12, "buildings_per_side": 16,
           "seed": 7},
 "mesh": {"subdivide": 80, "noise_m": 0.005, "seed": 7},
 "out": "capture", "size": [1280, 720], "lens": "pinhole", "hfov_deg": 70,
 "random_movers": 0, "supersample": 1, "seed": 7,
 "streams": [
  {"name": "walk0", "path": {"kind": "walk", "walk_from": [-78, 1.6, -4.5],
   "walk_to": [-42, 1.6, -3.5], "look_around_deg": 50, "pitch_deg": 8}},
  {"name": "walk1", "path": {"kind": "walk", "walk_from": [-2, 1.6, 4.5],
   "walk_to": [-38, 1.6, 3.5], "look_around_deg": 50, "pitch_deg": 8}},
  {"name": "walk2", "path": {"kind": "walk", "walk_from": [2, 1.6, -4.5],
   "walk_to": [38, 1.6, -3.5], "look_around_deg": 50, "pitch_deg": 8}},
  {"name": "walk3", "path": {"kind": "walk", "walk_from": [78, 1.6, 4.5],
   "walk_to": [42, 1.6, 3.5], "look_around_deg": 50, "pitch_deg": 8}},
  {"name": "mast0", "path": {"kind": "fixed", "eye": [-60, 5, 5.5], "target": [-52, 4, -6],
   "wobble_deg": 0.3}},
  {"name": "mast1", "path": {"kind": "fixed", "eye": [-20, 5, -5.5], "target": [-12, 4, 6],
   "wobble_deg": 0.3}},
  {"name": "mast2", "path": {"kind": "fixed", "eye": [20, 5, 5.5], "target": [28, 4, -6],
   "wobble_deg": 0.3}},
  {"name": "mast3", "path": {"kind": "fixed", "eye": [60, 5, -5.5], "target": [68, 4, 6],
   "wobble_deg": 0.3}}
 ]}
SPEC
echo "city_block_bench: synth, $frames frames per stream"
nice -n 15 "$fresco" synth "$work/city.json" --frames "$frames" --if-changed >/dev/null
project=$work/capture/project.json

echo "city_block_bench: the one-process run"
rm -rf "$work/whole"
nice -n 15 /usr/bin/time -v -o "$work/time-whole.txt" \
  "$fresco" run "$project" --out "$work/whole" --quiet "${sets[@]}"

echo "city_block_bench: $shards shards through Slurm"
bash "$here/one_node_cluster.sh" start "$work/cluster"
export SLURM_CONF=$work/cluster/slurm.conf
rm -rf "$work/job"
"$fresco" slurm "$project" --out "$work/job" --shards "$shards" --sbatch "--exclusive" \
  "${sets[@]}" >/dev/null
# Each job's command niced and timed (the scripts are meant to be edited).
logs=$work/job/logs
sed -i "s|^exec \(/[^ ]*\) |exec nice -n 15 /usr/bin/time -v -o $logs/time-prepass.txt \1 |" \
  "$work/job/prepass.sbatch"
sed -i "s|^exec \(/[^ ]*\) |exec nice -n 15 /usr/bin/time -v -o $logs/time-paint-\"\$I\".txt \1 |" \
  "$work/job/paint.sbatch"
sed -i "s|^exec \(/[^ ]*\) |exec nice -n 15 /usr/bin/time -v -o $logs/time-merge.txt \1 |" \
  "$work/job/merge.sbatch"
start=$(date +%s.%N)
prepass=$(sbatch --parsable "$work/job/prepass.sbatch")
paint=$(sbatch --parsable --dependency="afterok:$prepass" "$work/job/paint.sbatch")
merge=$(sbatch --parsable --dependency="afterok:$paint" "$work/job/merge.sbatch")
while [ -n "$(squeue -h -j "$prepass,$paint,$merge" 2>/dev/null)" ]; do sleep 2; done
elapsed=$(echo "$(date +%s.%N) - $start" | bc)
[ -f "$work/job/metrics.json" ] || { echo "city_block_bench: no merged output" >&2;
                                     tail -n 5 "$logs"/*.out >&2; exit 1; }

# wall seconds, CPU seconds (user + system), peak RSS in MB of one /usr/bin/time -v file.
figures() {
  awk -F': ' '/Elapsed/ {n = split($2, t, ":"); w = 0; for (i = 1; i <= n; ++i) w = w * 60 + t[i]}
              /User time/ {c += $2} /System time/ {c += $2}
              /Maximum resident/ {r = $2 / 1024}
              END {printf "%.1f %.1f %.0f\n", w, c, r}' "$1"
}
{
  read -r w c r < <(figures "$work/time-whole.txt")
  echo "one process: wall $w s, CPU $c s, peak RSS $r MB"
  read -r pw pc pr < <(figures "$logs/time-prepass.txt")
  echo "pre-pass job: wall $pw s, CPU $pc s, peak RSS $pr MB"
  for ((i = 0; i < shards; ++i)); do
    read -r sw sc sr < <(figures "$logs/time-paint-$i.txt")
    skipped=$(grep -o '"frames_skipped": [0-9]*' "$work/job/parts/$i/metrics.json" | head -n 1 |
              awk '{print $2}')
    echo "shard $i: wall $sw s, CPU $sc s, peak RSS $sr MB, frames skipped $skipped"
  done | tee "$work/shards.txt"
  read -r mw mc mr < <(figures "$logs/time-merge.txt")
  echo "merge job: wall $mw s, CPU $mc s, peak RSS $mr MB"
  awk -v w="$w" -v c="$c" -v r="$r" -v pw="$pw" -v pc="$pc" -v mw="$mw" -v mc="$mc" \
      -v el="$elapsed" '
    {sw = $4; sc = $7; sr = $11; n++; wsum += sw; csum += sc; rsum += sr
     if (sw > wmax) wmax = sw; if (sc > cmax) cmax = sc; if (sr > rmax) rmax = sr
     if (rmin == "" || sr < rmin) rmin = sr}
    END {
      printf "shards: CPU %.1f s in all (+ pre-pass %.1f + merge %.1f = %.1f s, %.2fx the one process)\n",
             csum, pc, mc, csum + pc + mc, (csum + pc + mc) / c
      printf "balance: largest shard / mean: wall %.2f, CPU %.2f\n", wmax / (wsum / n), cmax / (csum / n)
      printf "peak RSS per shard: %.0f-%.0f MB (%.2f-%.2fx the one process)\n", rmin, rmax, rmin / r, rmax / r
      printf "one node, the jobs one after another: %.0f s from submitting to the merge done\n", el
      printf "projected on %d nodes: pre-pass %.1f + slowest shard %.1f + merge %.1f = %.1f s wall (one process: %.1f s, %.1fx faster)\n",
             n, pw, wmax, mw, pw + wmax + mw, w, w / (pw + wmax + mw)
      printf "the same in CPU time (an idle node, one core): %.1f + %.1f + %.1f = %.1f s (one process: %.1f s, %.2fx faster)\n",
             pc, cmax, mc, pc + cmax + mc, c, c / (pc + cmax + mc)
    }' "$work/shards.txt"
  same=1
  maxdiff=0
  for f in "$work"/whole/*; do
    name=$(basename "$f")
    [ "$name" = metrics.json ] && continue
    cmp -s "$f" "$work/job/$name" && continue
    same=0
    case $name in
    *.png)
      # Peak absolute error, normalized to 0..1 (ImageMagick prints "Q (NORMALIZED)").
      d=$(compare -metric PAE "$f" "$work/job/$name" null: 2>&1 | sed 's/.*(\(.*\)).*/\1/' || true)
      maxdiff=$(awk -v a="$maxdiff" -v b="$d" 'BEGIN {v = b * 255; print (v > a ? v : a)}')
      ;;
    *) echo "merged $name differs from the one process's" ;;
    esac
  done
  if [ $same = 1 ]; then
    echo "merged == one process, byte for byte (painted.gltf, .bin, every page): max difference 0"
  else
    echo "merged pages: max difference $maxdiff levels"
  fi
} | tee "$work/figures.txt"
