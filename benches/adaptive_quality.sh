#!/usr/bin/env bash
# What adaptive antialiasing costs in quality (docs/RENDERING.md): per example scene, 16
# median-cut lights at 320 pixels wide, the default 4 spp with and without adaptive sampling,
# each against a 64-spp render of the same lights with every pixel fully sampled (relative MSE
# and mean FLIP, `ibl compare`), and the share of pixels adaptive sampling refined.
# Usage: benches/adaptive_quality.sh [IBL_BINARY]
set -euo pipefail
cd "$(dirname "$0")/.."
BIN=${1:-target/release/ibl}
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
for scene in bunny-apartment bunny-sky; do
  render() { "$BIN" render "assets/scenes/$scene.toml" --width 320 --mode lights -n 16 "$@" 2>/dev/null; }
  render -o "$OUT/truth.exr" --spp 64 --no-adaptive >/dev/null
  render -o "$OUT/fixed.exr" --no-adaptive >/dev/null
  refined=$(render -o "$OUT/adaptive.exr" --json |
    python3 -c 'import json, sys; d = json.load(sys.stdin); print(round(100 * d["refined_pixels"] / (d["width"] * d["height"])))')
  for run in fixed adaptive; do
    "$BIN" compare "$OUT/$run.exr" "$OUT/truth.exr" --json | python3 -c '
import json, sys
d = json.load(sys.stdin)
print("{} {}: relative MSE {:.2e}, FLIP {:.3f}".format(
    sys.argv[1], sys.argv[2], d["relative_mse"], d["flip"]["mean"]))' "$scene" "$run"
  done
  echo "$scene: adaptive refined $refined % of pixels"
done
