#!/usr/bin/env bash
# The reference renderer's error per sample and time, for one or more `ibl` binaries (for
# example one built before the floor's half-sphere environment sampling and one after;
# docs/RENDERING.md, "The environment samples of a floor"). Per scene: a 4096-sample reference
# from the first binary (seed 99), then each binary at each sample count with seeds 1 to 3,
# scored by the relative MSE of the image with the objects (`ibl compare`) and timed by
# `seconds_render`; prints the means over the seeds. 160 x 120, the scenes' own 4 bounces.
#
# Usage: bash benches/half_sphere.sh BIN [BIN...]   (SPPS="16 64" by default)
set -euo pipefail
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
for s in bunny-apartment bunny-sky; do
  "$1" render "assets/scenes/$s.toml" -o "$dir/ref.exr" --mode reference --width 160 \
    --spp 4096 --seed 99 --layers >/dev/null 2>&1
  for spp in ${SPPS:-16 64}; do
    for ibl in "$@"; do
      for seed in 1 2 3; do
        # The summary is read after the run: python starting on a pipe would take CPU
        # from the render's threads.
        "$ibl" render "assets/scenes/$s.toml" -o "$dir/t.exr" --mode reference \
          --width 160 --spp "$spp" --seed "$seed" --layers --json > "$dir/summary.json" 2>/dev/null
        seconds=$(python3 -c "import json, sys; print(json.load(sys.stdin)['seconds_render'])" \
          < "$dir/summary.json")
        error=$("$ibl" compare "$dir/t-with.exr" "$dir/ref-with.exr" --json |
          python3 -c "import json, sys; print(json.load(sys.stdin)['relative_mse'])")
        echo "$error $seconds"
      done | python3 -c "
import sys
rows = [tuple(map(float, line.split())) for line in sys.stdin]
error = sum(r[0] for r in rows) / len(rows)
seconds = sum(r[1] for r in rows) / len(rows)
print('$s $spp spp $ibl: relative MSE %.3e, %.3f s' % (error, seconds))"
    done
  done
done
