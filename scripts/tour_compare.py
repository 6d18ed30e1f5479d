#!/usr/bin/env python3
"""Compares two folders written by scripts/tour.sh file by file.

    python3 scripts/tour_compare.py /tmp/tour-before /tmp/tour-after

Every file must be byte-identical, except for timings: `seconds*` and `rays_per_second` values in
JSON, "N.NN s" and "M rays/s" in text, the `seconds` column of report.csv and the seconds columns of
the report.md tables. Prints one line per differing file: "timing only" or "DIFFERS";
exits 1 when any file differs beyond timings or exists on one side only.
"""

import csv
import io
import re
import sys
from pathlib import Path

NUMBER = re.compile(r'("?(seconds[a-z_]*|rays_per_second)"?\s*[:=]\s*)[-0-9.e+]+')


def masked(path: Path, text: str) -> str:
    if path.name == "report.csv":
        rows = list(csv.reader(io.StringIO(text)))
        if rows and "seconds" in rows[0]:
            k = rows[0].index("seconds")
            rows = [r[:k] + r[k + 1:] for r in rows]
        return repr(rows)
    text = NUMBER.sub(r"\1#", text)
    text = re.sub(r"\b\d+\.\d+ s\b", "# s", text)
    text = re.sub(r"\(\d+\.\d s\)", "(# s)", text)
    text = re.sub(r"[0-9.]+ M rays/s", "# M rays/s", text)
    if path.name == "report.md":
        # The seconds column: last in the comparison's tables, second in the renders' table.
        text = re.sub(r"\| [0-9.]+ \|\n", "| # |\n", text)
        text = re.sub(r"(\]\([^)]*\) \| )[0-9.]+( \|)", r"\1#\2", text)
    return text


def main(a: Path, b: Path) -> int:
    files_a = {p.relative_to(a) for p in a.rglob("*") if p.is_file()}
    files_b = {p.relative_to(b) for p in b.rglob("*") if p.is_file()}
    bad = 0
    for rel in sorted(files_a ^ files_b):
        print(f"ONE SIDE ONLY: {rel}")
        bad += 1
    same = 0
    for rel in sorted(files_a & files_b):
        x, y = (a / rel).read_bytes(), (b / rel).read_bytes()
        if x == y:
            same += 1
            continue
        tx, ty = x.decode("utf-8", "replace"), y.decode("utf-8", "replace")
        if masked(rel, tx) == masked(rel, ty):
            print(f"timing only: {rel}")
        else:
            print(f"DIFFERS: {rel}")
            bad += 1
    print(f"{same} files byte-identical, {bad} differing beyond timings")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(Path(sys.argv[1]), Path(sys.argv[2])))
