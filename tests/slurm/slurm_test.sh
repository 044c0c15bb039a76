#!/usr/bin/env bash
# `fresco slurm --submit` on a real (one-node) Slurm cluster: the array of shards and the merge
# after it, compared byte for byte with the unsharded run. Starts the cluster with
# one_node_cluster.sh in a temporary folder and stops the daemons it started, by PID, on exit.
# Exit 77 (skipped) without Slurm and munge or without root.
# Usage: bash tests/slurm/slurm_test.sh [FRESCO]
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
fresco=$(realpath "${1:-${FRESCO_BINARY:-build/app/fresco}}")
work=$(mktemp -d /tmp/fresco-slurm-test.XXXXXX)
cleanup() {
  bash "$here/one_node_cluster.sh" stop "$work/cluster" || true
  rm -rf "$work"
}
trap cleanup EXIT

set +e
bash "$here/one_node_cluster.sh" start "$work/cluster"
code=$?
set -e
if [ $code -eq 77 ]; then echo "slurm_test: skipped (no Slurm/munge, or not root)"; exit 77; fi
[ $code -eq 0 ] || exit 1
export SLURM_CONF=$work/cluster/slurm.conf

# A small capture of two streams (the shards and the merge take seconds).
cat > "$work/spec.json" <<'SPEC'
{"scene": "builtin:cube-room", "out": "capture", "size": [240, 180], "frames": 30, "seed": 5,
 "streams": [{"name": "fixed", "path": {"kind": "fixed"}, "lens": "opencv5", "hfov_deg": 80},
             {"name": "hand", "path": {"kind": "handheld", "turns": 0.75}, "lens": "pinhole"}]}
SPEC
"$fresco" synth "$work/spec.json" >/dev/null
project=$work/capture/project.json
"$fresco" run "$project" --out "$work/whole" --quiet

ids=$("$fresco" slurm "$project" --out "$work/job" --shards 3 --submit --sbatch "--time=10")
echo "$ids"
paint=$(echo "$ids" | awk '$1 == "paint" {print $2}')
merge=$(echo "$ids" | awk '$1 == "merge" {print $2}')
[ -n "$paint" ] && [ -n "$merge" ] || { echo "slurm_test: no job ids in: $ids" >&2; exit 1; }
for _ in $(seq 600); do
  [ -z "$(squeue -h -j "$paint,$merge" 2>/dev/null)" ] && break
  sleep 0.5
done
if [ -n "$(squeue -h -j "$paint,$merge" 2>/dev/null)" ]; then
  echo "slurm_test: jobs still queued after 300 s" >&2; squeue >&2; exit 1
fi
status=0
for f in "$work"/whole/*; do
  name=$(basename "$f")
  [ "$name" = metrics.json ] && continue
  if ! cmp -s "$f" "$work/job/$name"; then
    echo "slurm_test: $name differs from the unsharded run's (or is missing)" >&2
    status=1
  fi
done
[ -f "$work/job/metrics.json" ] || { echo "slurm_test: no merged metrics.json" >&2; status=1; }
# The defaults need the whole-capture pre-pass: one job ran it, before the array.
prepass=$(echo "$ids" | awk '$1 == "prepass" {print $2}')
[ -n "$prepass" ] && [ -f "$work/job/prepass.json" ] ||
  { echo "slurm_test: no pre-pass job or no DIR/prepass.json" >&2; status=1; }
for i in 0 1 2; do
  grep -q "\"index\": $i" "$work/job/parts/$i/metrics.json" ||
    { echo "slurm_test: part $i has no shard index" >&2; status=1; }
done
if [ $status -ne 0 ]; then tail -n 5 "$work"/job/logs/*.out >&2 || true; exit 1; fi
echo "slurm_test: a pre-pass and 3 shards on Slurm, merged == unsharded"
