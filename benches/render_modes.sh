#!/usr/bin/env bash
# The render modes' speed against the reference (issue 13, BENCHMARKS.md "Render modes at their
# default settings"): per example scene, ROUNDS rounds of the reference, lights and hybrid modes
# at their default settings, 320 pixels wide, each run after a PAUSE (a shared machine's speed
# drifts under sustained load), the fastest `seconds_render` of each kept, and the ratios.
# Usage: benches/render_modes.sh [IBL_BINARY] [ROUNDS] [PAUSE_SECONDS]
set -euo pipefail
cd "$(dirname "$0")/.."
BIN=${1:-target/release/ibl}
ROUNDS=${2:-3}
PAUSE=${3:-8}
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
seconds() { python3 -c 'import json, sys; print(json.load(sys.stdin)["seconds_render"])'; }
for scene in bunny-apartment bunny-sky; do
  declare -A best=()
  for _ in $(seq "$ROUNDS"); do
    for mode in reference lights hybrid; do
      sleep "$PAUSE"
      lights=()
      [ "$mode" != reference ] && lights=(-n 16)
      # The summary goes to a file and is read after the run: a reader started on a pipe
      # (python's start-up, ~50 ms of CPU) would compete with the render's threads.
      "$BIN" render "assets/scenes/$scene.toml" -o "$OUT/o.exr" --width 320 --mode "$mode" \
        "${lights[@]}" --json > "$OUT/summary.json" 2>/dev/null
      t=$(seconds < "$OUT/summary.json")
      best[$mode]=$(python3 -c "print(min(${best[$mode]:-1e9}, $t))")
    done
  done
  python3 - "$scene" "${best[reference]}" "${best[lights]}" "${best[hybrid]}" <<'PY'
import sys
scene, ref, lights, hybrid = sys.argv[1], *map(float, sys.argv[2:])
print(f"{scene}: reference {ref:.3f} s, lights {lights:.3f} s ({ref / lights:.1f}x), "
      f"hybrid {hybrid:.3f} s ({ref / hybrid:.1f}x)")
PY
  unset best
done
