#!/usr/bin/env bash
# Fill fuzz/corpus/<target>/ with small valid inputs and the hostile files, so that every target
# starts from inputs that reach deep into its parser. Images are written small (16 to 32 pixels
# wide) so that the fuzzer's mutations stay cheap.
#
# Usage (from the repository root): bash fuzz/seed.sh [path/to/ibl]
# The `ibl` binary (default target/release/ibl) writes the small images and textures.
set -euo pipefail
ibl=${1:-target/release/ibl}
[ -x "$ibl" ] || { echo "seed.sh: no ibl binary at $ibl (cargo build --release)" >&2; exit 2; }
c=fuzz/corpus
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$c"/{hdr,pfm,exr,mesh_glb,mesh_obj,room_marks,room_file,scene_file,batch_spec,room_edits,ktx2,dds,ies,ldt,light_files,sh_file,exposure_times}

# Images: the hostile files and two probes written small in each format.
for ext in hdr pfm exr; do
  cp tests/hostile/*."$ext" "$c/$ext/" 2>/dev/null || true
  for p in sky apartment; do
    "$ibl" convert "assets/probes/$p.exr" "$c/$ext/$p-16.$ext" --width 16 >/dev/null
  done
done
"$ibl" convert assets/probes/sky.exr "$c/hdr/sky-cross.hdr" --to cube-hcross --face-size 4 >/dev/null

# Meshes.
cp assets/models/*.glb crates/ibl-io/tests/data/meshes/*.gltf "$c/mesh_glb/"
for obj in crates/ibl-io/tests/data/meshes/*.obj assets/outdoor/courtyard/model.obj; do
  mtl="${obj%.obj}.mtl"
  # The target splits its input at the first NUL: the OBJ, then the material library.
  if [ -f "$mtl" ]; then
    { cat "$obj"; printf '\0'; cat "$mtl"; } >"$c/mesh_obj/$(basename "$obj")"
  else
    cp "$obj" "$c/mesh_obj/"
  fi
done

# Text formats: every bundled file of each kind.
cp assets/rooms/apartment/marks.json "$c/room_marks/"
cp assets/rooms/apartment/room.toml "$c/room_file/"
[ -f assets/rooms/synthetic/room.toml ] && cp assets/rooms/synthetic/room.toml "$c/room_file/synthetic.toml"
for s in assets/scenes/*.toml assets/scenes/*/*.toml assets/rooms/apartment/bunny-patches.toml assets/outdoor/courtyard/scene.toml; do
  cp "$s" "$c/scene_file/$(echo "$s" | tr / _)"
done
cp assets/batch/*.toml "$c/batch_spec/"
cp assets/rooms/apartment/edits*.toml "$c/room_edits/"

# Textures: a small specular chain, a lat-long chain, an irradiance cube and a DFG table in each
# container and texel format.
for f in rgba16f rgba32f rgb9e5; do
  for ext in ktx2 dds; do
    "$ibl" prefilter assets/probes/sky.exr -o "$tmp/spec-$f.$ext" --size 4 --samples 16 --format "$f" \
      --latlong "$tmp/ll-$f.$ext" --latlong-width 8 --irradiance "$tmp/irr-$f.$ext" \
      --irradiance-size 2 --dfg "$tmp/dfg-$f.$ext" --dfg-size 4 >/dev/null
  done
done
cp "$tmp"/*.ktx2 "$c/ktx2/"
cp "$tmp"/*.dds "$c/dds/"

# Light files: light sets of every method and a hybrid, the room's area lights.
for m in median-cut lightgen variance-minimization; do
  "$ibl" lights assets/probes/sky.exr -n 4 --method "$m" -o "$c/light_files/$m.json" >/dev/null
done
"$ibl" room lights assets/rooms/apartment/room.toml -n 4 -o "$c/light_files/area.json" >/dev/null

# SH files in every format.
for f in json threejs filament unity webxr arkit gltf-ext; do
  "$ibl" sh assets/probes/apartment.exr --format "$f" -o "$c/sh_file/$f.txt" >/dev/null
done

# Exposure-time lists: plain, OpenCV's list.txt, two columns with a comment.
printf '1/250, 1/60\n0.25\n' >"$c/exposure_times/plain.txt"
printf 'a.jpg 0.03125\nb.jpg 0.0625\nIMG_0003.JPG 0.125\n' >"$c/exposure_times/list.txt"
printf '# name seconds\na.jpg 1/250\nb.jpg 0.25\nIMG_0003.JPG 2\n' >"$c/exposure_times/two.txt"

# Photometry.
cp assets/photometry/ies/*.ies crates/ibl-io/tests/data/photometry/*.ies "$c/ies/"
cp crates/ibl-io/tests/data/photometry/*.ldt "$c/ldt/"

for t in "$c"/*/; do printf '%-12s %4d files\n' "$(basename "$t")" "$(ls "$t" | wc -l)"; done
