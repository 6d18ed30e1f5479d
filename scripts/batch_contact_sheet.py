"""A contact sheet of a batch: each probe's ``lights.png`` (or ``preview.png``) in a grid.

Usage: python scripts/batch_contact_sheet.py OUT_FOLDER SHEET.png [--columns 2]

OUT_FOLDER is a batch's output folder (``[output] folder`` of the spec); the probes are taken in
the order of its ``results.jsonl``, failed rows left out. Needs the ``iblkit`` wheel and numpy.
The docs' picture (docs/BATCH.md) is

    ibl batch assets/batch/bundled.toml
    python scripts/batch_contact_sheet.py batch-out/bundled docs/images/batch/contact-sheet.png
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

import iblkit

GAP = 4  # pixels between tiles (white)


def shrink(image: np.ndarray, k: int) -> np.ndarray:
    """The mean of each k x k block (linear values, so the box filter is energy-conserving)."""
    h, w = image.shape[0] // k * k, image.shape[1] // k * k
    return image[:h, :w].reshape(h // k, k, w // k, k, 3).mean(axis=(1, 3))


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path, help="the batch's output folder")
    parser.add_argument("sheet", type=Path, help="the PNG to write")
    parser.add_argument("--columns", type=int, default=2)
    parser.add_argument("--shrink", type=int, default=4, help="box-filter each tile by this factor")
    args = parser.parse_args()
    rows_file = args.out / "results.jsonl"
    try:
        rows = [json.loads(line) for line in rows_file.read_text().splitlines() if line]
    except OSError as e:
        print(f"batch_contact_sheet: {rows_file}: {e}", file=sys.stderr)
        return 2
    tiles = []
    for row in rows:
        if row.get("status") != "ok":
            continue
        folder = args.out / row["id"]
        picture = next((folder / n for n in ("lights.png", "preview.png") if (folder / n).is_file()), None)
        if picture is not None:
            tiles.append(shrink(iblkit.read_image(picture), max(1, args.shrink)))
    if not tiles:
        print(f"batch_contact_sheet: {args.out}: no lights.png or preview.png", file=sys.stderr)
        return 2
    h = max(t.shape[0] for t in tiles)
    w = max(t.shape[1] for t in tiles)
    cols = max(1, min(args.columns, len(tiles)))
    nrows = -(-len(tiles) // cols)
    sheet = np.ones((nrows * (h + GAP) - GAP, cols * (w + GAP) - GAP, 3), np.float32)
    for k, tile in enumerate(tiles):
        y, x = (k // cols) * (h + GAP), (k % cols) * (w + GAP)
        sheet[y : y + tile.shape[0], x : x + tile.shape[1]] = tile
    # The tiles are decoded sRGB PNGs (linear, in [0, 1]): written back unchanged with clamp.
    iblkit.write_image(args.sheet, sheet, exposure=0.0, curve="clamp")
    print(f"{len(tiles)} probes -> {args.sheet}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
