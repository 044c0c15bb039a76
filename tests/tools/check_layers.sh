#!/usr/bin/env bash
# The layers point down (docs/architecture.md, "Rules that keep the layers apart"): fails
# naming each include that points up. Usage: check_layers.sh SOURCE_DIR
set -u
cd "${1:?usage: check_layers.sh SOURCE_DIR}"
problems=0
# check DIRS... -- PATTERN WHY: every include in DIRS matching PATTERN is a problem.
check() {
  local dirs=() pattern why
  while [ "$1" != "--" ]; do dirs+=("$1"); shift; done
  pattern=$2 why=$3
  local hits
  hits=$(grep -rnE "^#include [<\"]($pattern)" "${dirs[@]}" --include='*.h' --include='*.cc' || true)
  if [ -n "$hits" ]; then
    echo "$why:"
    echo "$hits"
    problems=$((problems + $(echo "$hits" | wc -l)))
  fi
}
check pipeline/settings -- "pipeline/(core|live|paint|run|render|synth|eval|rephoto|poses)/|calib/|ui/|app/" \
  "pipeline/settings/ is plain data on the ground floor: it includes only itself"
check pipeline/core pipeline/live -- "pipeline/(paint|run|render|eval|rephoto|poses)/" \
  "pipeline/core and pipeline/live stay below the painter and the job layer"
check pipeline calib -- "GL/|GLFW/|imgui|ui/|app/" \
  "pipeline/ and calib/ are headless: no GL, GLFW, ImGui, UI or CLI"
echo "check_layers: $problems include(s) pointing up"
[ "$problems" -eq 0 ]
