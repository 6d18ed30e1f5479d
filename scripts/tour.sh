#!/usr/bin/env bash
# Runs every command of the README's tour on fixed inputs (the bundled probes and example scenes;
# capture inputs made from a probe) into one folder, so that two builds of `ibl` can be compared
# file by file (issue 14: "behaviour unchanged").
#
#   scripts/tour.sh IBL_BINARY OUT_DIR
#   scripts/tour.sh /work/baseline/ibl /tmp/tour-before
#   scripts/tour.sh target/release/ibl /tmp/tour-after
#   python3 scripts/tour_compare.py /tmp/tour-before /tmp/tour-after
#
# Renders and the demo run at reduced sizes and sample counts to keep the tour to a few minutes.
# Every command's stdout, stderr and exit status land beside its outputs (`NN-name.out`,
# `.err`, `.status`); timings in them differ from run to run, everything else must not.
set -uo pipefail

if [ $# -ne 2 ]; then
  echo "usage: $0 IBL_BINARY OUT_DIR" >&2
  exit 2
fi
IBL=$(realpath "$1")
OUT=$2
REPO=$(cd "$(dirname "$0")/.." && pwd)
rm -rf "$OUT"
mkdir -p "$OUT"
OUT=$(realpath "$OUT")
cd "$OUT" || exit 1
P="$REPO/assets/probes"
S="$REPO/assets/scenes"
step=0

# run NAME ARGS...: runs `ibl ARGS...` in $OUT, keeping stdout, stderr and the exit status.
run() {
  local name=$1
  shift
  step=$((step + 1))
  local tag
  tag=$(printf '%02d-%s' "$step" "$name")
  "$IBL" "$@" >"$tag.out" 2>"$tag.err"
  echo $? >"$tag.status"
  echo "$tag: exit $(cat "$tag.status")"
}

# The tour, in the README's order.
run info info "$P/esplanade.exr"
run info-json info "$P/sky.hdr" --json
run convert-hcross convert "$P/esplanade.exr" cross.exr --to cube-hcross
run convert-faces convert "$P/esplanade.exr" 'sky_{face}.hdr' --to cube-faces
run make-ball convert "$P/sky.exr" ball.exr --to mirror-ball --width 512
run convert-ball convert ball.exr ball-probe.exr --from mirror-ball --to latlong --width 1024 --rotate 90,0,0
run convert-threejs convert "$P/sky.exr" three.hdr --frame threejs
run preview preview "$P/sunset.exr" sunset.png --tonemap aces
run lights lights "$P/esplanade.exr" -n 16 -o lights.json
run lights-io lights "$P/sky.exr" -n 24 --method irradiance-optimization -o l.gltf -o l.xml --overlay l.png
run lights-hybrid lights "$P/sky.exr" -n 1 --method irradiance-optimization --ambient-sh 3 -o sun+sh9.json --json
run lights-frames lights "$P/apartment.exr" -n 12 --method adaptive-median-cut -o scene.pbrt -o apt.glb --frame blender
run eval eval "$P/sky.exr" "$P/apartment.exr" --n 1,2,4,16,64 --out eval
run eval-hybrid eval "$P/sky.exr" --methods sun+sh3,sh3,lightgen+sh3,lightgen --n 1,4,16 --out hybrid
run irradiance-sh irradiance "$P/sky.exr" -o irr.exr --method sh --bands 3
run irradiance-faces irradiance "$P/sky.exr" -o 'irr_{face}.hdr' --to cube-faces
run irradiance-csv irradiance "$P/night.exr" --normals 2000 --method fast --csv E.csv --json
run sh-filament sh "$P/sky.exr" --format filament -o sh.txt
run sh-convert sh --from filament sh.txt --format threejs
run sh-json sh "$P/apartment.exr" --bands 5 --irradiance --window hann -o sh5.json
run render-sky render "$S/bunny-sky.toml" -o bunny.exr --width 160 --spp 8
run render-pano render "$S/bunny-sky.toml" -o pano.exr --panorama --width 256 --spp 4
run render-lights render "$S/bunny-apartment.toml" -o b.exr --mode lights -n 16 --method lightgen --width 160 --spp 8
run render-given render "$S/bunny-sky.toml" -o given.exr --mode lights --lights lights.json --shadows soft --width 160 --spp 4
run render-hybrid render "$S/bunny-sky.toml" -o h.exr --mode hybrid -n 8 --layers --json --width 160 --spp 4
run compare compare b.exr bunny.exr --error-image err.png
run compare-json compare given.exr bunny.exr --metric relmse --error-image relmse.exr --json

# Capture inputs made from a probe: three 8-bit exposures, two mirror-ball views, a dual fisheye.
run bracket-0 preview "$P/sunset.exr" IMG_0.png --exposure -6 --tonemap clamp
run bracket-1 preview "$P/sunset.exr" IMG_1.png --exposure -3 --tonemap clamp
run bracket-2 preview "$P/sunset.exr" IMG_2.png --exposure 0 --tonemap clamp
run capture-merge capture merge IMG_0.png IMG_1.png IMG_2.png --times 1/64,1/8,1 -o merged.exr
run capture-merge-aligned capture merge IMG_0.png IMG_1.png IMG_2.png --times 1/64,1/8,1 -o merged-lin.exr --response linear --align --deghost --json
run capture-merge-given capture merge IMG_0.png IMG_1.png IMG_2.png --times 1/64,1/8,1 -o merged-given.exr --response merged-response.csv --weighting noise-aware
run make-side convert "$P/sky.exr" side.exr --to mirror-ball --width 512 --rotate -90,0,0
run capture-ball capture ball ball.exr side.exr --yaw 0,90 -o ball-merged.exr --width 256
run make-dual convert "$P/esplanade.exr" gear360.png --to dual-fisheye --fov 195 --width 1024
run capture-fisheye capture fisheye gear360.png -o fisheye.exr --fov 195 --width 512

# The reconstructed room, its manipulations, the outdoor sequence, a batch.
R="$REPO/assets/rooms/apartment"
run room-calibrate room calibrate "$R/marks.json" -o room.toml
run room-estimate room estimate "$R/room.toml" -o apt
run room-lights room lights "$R/room.toml" -n 32 -o apt-lights.json
run room-render room render "$R/room.toml" --edit "$R/edits.toml" -o after.png --before before.png
run room-render-view room render "$R/room.toml" --edit "$R/edits-view.toml" -o view.exr --json
run outdoor outdoor "$REPO/assets/outdoor/courtyard/scene.toml" --out day
mkdir -p batch-probes
cp "$P/sky.exr" "$P/night.exr" batch-probes/
printf '[input]\nfolder = "batch-probes"\n[output]\nfolder = "batch-out"\n[steps.lights]\nn = 16\n[steps.sh]\n[steps.preview]\n' >batch.toml
run batch batch batch.toml --json

# The demo on one probe and one scene.
mkdir -p demo-probes demo-scenes
cp "$P/sky.exr" demo-probes/
sed -e "s#\.\./probes/#$P/#; s#\.\./models/#$REPO/assets/models/#" "$S/bunny-sky.toml" >demo-scenes/bunny-sky.toml
run demo demo --out demo-out --probes demo-probes --scenes demo-scenes

# Bad input: the exit status and the message.
run bad-missing info /nonexistent/probe.exr
run bad-mapping convert "$P/sky.exr" x.exr --to nope
run bad-count lights "$P/sky.exr" -n 3 -o x.json
run bad-overwrite convert "$P/sky.exr" "$P/sky.exr"
echo "tour finished in $OUT"
