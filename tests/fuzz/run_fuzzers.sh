#!/usr/bin/env bash
# Runs every fuzz target for SECONDS each, one after the other, and prints one line per
# target: executions per second, corpus size, coverage, and whether it found a crash
# (README "Reliability: fuzzing and sanitizers"). BUILD is a FRESCO_FUZZ build folder.
#   bash tests/fuzz/run_fuzzers.sh BUILD [SECONDS=60] [TARGET...]
set -uo pipefail
build=$(cd "${1:?usage: run_fuzzers.sh BUILD [SECONDS] [TARGET...]}" && pwd)
seconds=${2:-60}
shift $(( $# < 2 ? $# : 2 ))
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(project colmap_text tum cameramodel board_spec gltf)
fuzz="$build/tests/fuzz"
source_dir=$(cd "$(dirname "$0")/../.." && pwd)
/usr/bin/python3 "$source_dir/tests/fuzz/seed_corpora.py" "$source_dir" "$source_dir/../shared/data" \
  "$fuzz/seeds" || exit 1
status=0
printf "%-12s %8s %9s %10s %7s %s\n" target seconds exec/s corpus cov result
for t in "${targets[@]}"; do
  mkdir -p "$fuzz/corpus/$t" "$fuzz/crashes"
  log="$fuzz/$t.log"
  "$fuzz/${t}_fuzz" -max_total_time="$seconds" -max_len=65536 -timeout=10 -rss_limit_mb=2048 \
    -print_final_stats=1 -artifact_prefix="$fuzz/crashes/$t-" \
    "$fuzz/corpus/$t" "$fuzz/seeds/$t" > "$log" 2>&1
  code=$?
  rate=$(grep -oE "average_exec_per_sec: +[0-9]+" "$log" | grep -oE "[0-9]+$")
  cov=$(grep -E "^#[0-9]+" "$log" | tail -1 | grep -oE "cov: [0-9]+" | grep -oE "[0-9]+")
  files=$(ls "$fuzz/corpus/$t" | wc -l)
  bytes=$(( $(cat "$fuzz/corpus/$t"/* 2>/dev/null | wc -c) / 1024 ))
  result="ok"
  if [ $code -ne 0 ]; then
    result="FOUND: $(grep -m1 -oE "ERROR: .*|runtime error: .*|FUZZ_CHECK failed: .*" "$log") ($log)"
    status=1
  fi
  printf "%-12s %8s %9s %10s %7s %s\n" "$t" "$seconds" "${rate:-?}" "${files}f/${bytes}K" "${cov:-?}" \
    "$result"
done
exit $status
