#!/usr/bin/env bash
# The render study's light renders converged: each method at N lights (soft shadows) rendered
# with SPP samples per pixel, no adaptive antialiasing, against the study's reference (512 spp,
# one bounce, 128 x 96), so that the figure is the light approximation's own error and not the
# light render's sampling noise (the study renders lights at their default 4 adaptive samples).
# Prints scene, mode, method, N, relative MSE, its multiple of the reference's noise floor (as
# the study states it) and mean FLIP. MODES (default "lights") may add "hybrid": the method's
# lights plus the scene's SH ambient, as the study's hybrids.
#
# Usage: [MODES="lights hybrid"] bash benches/study_converged.sh target/release/ibl [SPP] [N...]
set -euo pipefail
ibl=$1
spp=${2:-64}
shift 2 || true
counts=${*:-16 32}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
declare -A floor=([bunny-apartment]=4.25e-5 [bunny-sky]=6.09e-5)
for s in bunny-apartment bunny-sky; do
  "$ibl" render "assets/scenes/$s.toml" -o "$dir/ref.exr" --mode reference --spp 512 --bounces 1 \
    --width 128 --layers >/dev/null 2>&1
  for m in median-cut adaptive-median-cut lightgen variance-minimization irradiance-optimization; do
    for n in $counts; do
      for mode in ${MODES:-lights}; do
        "$ibl" render "assets/scenes/$s.toml" -o "$dir/l.exr" --mode "$mode" --method "$m" \
          -n "$n" --bounces 1 --width 128 --layers --spp "$spp" --no-adaptive >/dev/null 2>&1
        "$ibl" compare "$dir/l-with.exr" "$dir/ref-with.exr" --json | python3 -c "
import json, sys
d = json.load(sys.stdin)
print('$s $mode $m $n %.3e %.1fx %.3f' % (d['relative_mse'], d['relative_mse'] / ${floor[$s]}, d['flip']['mean']))"
      done
    done
  done
done
