#!/usr/bin/env bash
# How each command's time and peak memory grow with the probe's size and with N (issue 13,
# "Cost as probes grow"). The probe is assets/probes/sky.exr resampled to each width with
# `ibl convert` (energy-conserving); every command runs as a whole process, as a user runs it,
# under /usr/bin/time (wall seconds, peak resident MB), at most LIMIT seconds each.
#
# Usage: scripts/bench_growth.sh            (IBL=target/release/ibl, LIMIT=300)
# Prints two Markdown tables (the ones in BENCHMARKS.md) on stdout.
set -euo pipefail
cd "$(dirname "$0")/.."
IBL=${IBL:-target/release/ibl}
LIMIT=${LIMIT:-300}
WIDTHS=${WIDTHS:-"512 1024 2048 4096"}
[ -x "$IBL" ] || { echo "bench_growth: no $IBL (cargo build --release first)" >&2; exit 2; }
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
for w in $WIDTHS; do
  "$IBL" convert assets/probes/sky.exr "$WORK/sky$w.exr" --to latlong --width "$w" >/dev/null
done

measure() { # measure ARGS...: "wall s / peak MB" of `ibl ARGS...`
  if /usr/bin/time -f "%e %M" -o "$WORK/time" timeout "$LIMIT" "$IBL" "$@" >/dev/null 2>&1; then
    awk '{ printf "%.2f s / %.0f MB", $1, $2 / 1024 }' "$WORK/time"
  else
    echo "> $LIMIT s"
  fi
}

row() { # row NAME ARGS-with-PROBE-and-OUT: one table row over the widths
  local name=$1
  shift
  local line="| $name |"
  for w in $WIDTHS; do
    local args=()
    for a in "$@"; do
      a=${a//PROBE/$WORK/sky$w.exr}
      args+=("${a//OUT/$WORK/out$w}")
    done
    line+=" $(measure "${args[@]}") |"
  done
  echo "$line"
}

echo "Probe width (lat-long W x W/2): $WIDTHS; $(nproc) cores; wall time / peak memory"
echo
printf '| command |'; for w in $WIDTHS; do printf ' %s x %s |' "$w" $((w / 2)); done; echo
printf '|---|'; for _ in $WIDTHS; do printf -- '---:|'; done; echo
row '`info`' info PROBE
row '`convert --to cube-hcross`' convert PROBE OUT.exr --to cube-hcross
row '`preview`' preview PROBE OUT.png
row '`sh --bands 3`' sh PROBE --bands 3 -o OUT.json
row '`irradiance --csv` (20000 exact normals)' irradiance PROBE --csv OUT.csv
row '`prefilter` (64^2 faces, 64 samples)' prefilter PROBE -o OUT.ktx2
for m in median-cut adaptive-median-cut lightgen variance-minimization irradiance-optimization; do
  row "\`lights -n 16 --method $m\`" lights PROBE -n 16 --method "$m" -o OUT.json
done
row '`eval --methods median-cut --n 16`' eval PROBE --methods median-cut --n 16 --out OUT

echo
echo "N lights on the 1024 x 512 probe; wall time / peak memory"
echo
NS="4 16 64 256"
printf '| method |'; for n in $NS; do printf ' N = %s |' "$n"; done; echo
printf '|---|'; for _ in $NS; do printf -- '---:|'; done; echo
for m in median-cut adaptive-median-cut lightgen variance-minimization irradiance-optimization; do
  line="| $m |"
  for n in $NS; do
    line+=" $(measure lights "$WORK/sky1024.exr" -n "$n" --method "$m" -o "$WORK/n.json") |"
  done
  echo "$line"
done
