#!/usr/bin/env bash
# The batch benchmark of issue 19: probes per second for 16 median-cut lights + SH9 + an ACES
# preview per probe, through
#   1. a shell loop of `ibl lights`, `ibl sh` and `ibl preview` (the baseline), one probe at a
#      time and two at a time (xargs -P 2);
#   2. `ibl batch` with --jobs 1 and --jobs 2;
#   3. `python -m iblkit.batch` on a local Dask cluster of 1 and of 2 workers (cluster start
#      included, as a user sees it).
# Every path does the same work on the same probes: the bundled probes (assets/probes/*.exr),
# each copied COPIES times so that a run lasts long enough to time (default 4: 20 probes).
#
# Usage: scripts/bench_batch.sh [COPIES]
#   IBL=target/release/ibl        the ibl binary (build it with cargo build --release)
#   PYTHON=python3                a Python with the iblkit wheel (maturin build --release) and
#                                 dask[distributed] installed; unset or missing: Dask rows skipped
# Prints a Markdown table (the one in BENCHMARKS.md) on stdout.
set -euo pipefail
cd "$(dirname "$0")/.."
COPIES=${1:-4}
IBL=${IBL:-target/release/ibl}
PYTHON=${PYTHON:-python3}
[ -x "$IBL" ] || { echo "bench_batch: no $IBL (cargo build --release first)" >&2; exit 2; }

WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
mkdir -p "$WORK/probes"
for k in $(seq 1 "$COPIES"); do
  for p in assets/probes/*.exr; do
    cp "$p" "$WORK/probes/c${k}_$(basename "$p")"
  done
done
PROBES=$(find "$WORK/probes" -name '*.exr' | wc -l)

spec() { # spec OUT_FOLDER > spec.toml
  cat <<EOF
[input]
folder = "probes"
[output]
folder = "$1"
[steps.lights]
n = 16
method = "median-cut"
[steps.sh]
bands = 3
[steps.preview]
curve = "aces"
EOF
}

one_probe() { # one_probe IBL OUT PROBE: the three commands a shell loop runs per probe
  local ibl=$1 out=$2 p=$3
  local id
  id=$(basename "$p" .exr)
  mkdir -p "$out/$id"
  "$ibl" lights "$p" -n 16 --method median-cut -o "$out/$id/lights.json" >/dev/null
  "$ibl" sh "$p" --bands 3 -o "$out/$id/sh.json" >/dev/null
  "$ibl" preview "$p" "$out/$id/preview.png" --tonemap aces >/dev/null
}
export -f one_probe

seconds() { # seconds COMMAND...: wall time of COMMAND in seconds
  local t0 t1
  t0=$(date +%s.%N)
  "$@" >/dev/null 2>&1 || { echo "bench_batch: failed: $*" >&2; exit 1; }
  t1=$(date +%s.%N)
  awk -v a="$t0" -v b="$t1" 'BEGIN { print b - a }'
}

loop_serial() { for p in "$WORK"/probes/*.exr; do one_probe "$IBL" "$WORK/loop1" "$p"; done; }
loop_parallel() {
  find "$WORK/probes" -name '*.exr' -print0 |
    xargs -0 -P 2 -I{} bash -c 'one_probe "$0" "$1" "$2"' "$IBL" "$WORK/loop2" {}
}
batch() { spec "out-ibl$1" > "$WORK/ibl$1.toml"; "$IBL" batch "$WORK/ibl$1.toml" --jobs "$1"; }
dask() {
  spec "out-dask$1" > "$WORK/dask$1.toml"
  "$PYTHON" -m iblkit.batch "$WORK/dask$1.toml" --workers "$1"
}

rows=()
base=$(seconds loop_serial)
rows+=("shell loop of ibl lights/sh/preview, 1 at a time|$base")
rows+=("shell loop, 2 at a time (xargs -P 2)|$(seconds loop_parallel)")
rows+=("ibl batch --jobs 1|$(seconds batch 1)")
rows+=("ibl batch --jobs 2|$(seconds batch 2)")
if "$PYTHON" -c 'import iblkit, dask.distributed' 2>/dev/null; then
  rows+=("python -m iblkit.batch --workers 1 (Dask)|$(seconds dask 1)")
  rows+=("python -m iblkit.batch --workers 2 (Dask)|$(seconds dask 2)")
else
  echo "bench_batch: $PYTHON lacks iblkit or dask.distributed: Dask rows skipped" >&2
fi

echo "$PROBES probes ($COPIES copies of the bundled five), $(nproc) cores"
echo
echo "| path | seconds | probes/s | speed-up vs the serial shell loop |"
echo "|---|---:|---:|---:|"
for row in "${rows[@]}"; do
  name=${row%|*}
  t=${row##*|}
  awk -v n="$name" -v t="$t" -v p="$PROBES" -v b="$base" \
    'BEGIN { printf "| %s | %.2f | %.2f | %.2fx |\n", n, t, p / t, b / t }'
done
