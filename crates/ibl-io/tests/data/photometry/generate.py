#!/usr/bin/env python3
"""Writes the synthetic photometric files of this folder (standard library only).

Each file's intensity is a closed-form function, so the tests (crates/ibl-io/tests/photometry.rs)
know the candela value at every expanded node and the luminous flux the table must integrate to.
One IES file per LM-63 horizontal symmetry and edition, one EULUMDAT file per Isym; README.md lists
them with their formulas and fluxes. Values are written to 6 significant digits.
"""

import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))


def g(x):
    return f"{x:.6g}"


def steps(first, last, step):
    n = round((last - first) / step)
    return [first + k * step for k in range(n + 1)]


def wrap(values, per_line=10, sep=" "):
    rows = [values[k:k + per_line] for k in range(0, len(values), per_line)]
    return "\n".join(sep.join(g(v) for v in row) for row in rows)


def ies(name, first_line, header, tilt, head_numbers, ballast, vertical, horizontal, f, scale=1.0, sep=" "):
    """`f(gamma_deg, c_deg)` in cd; the file holds f / scale (the multiplier times factors)."""
    lines = ([first_line] if first_line else []) + header + [tilt]
    lines.append(" ".join(g(v) for v in head_numbers))
    lines.append(" ".join(g(v) for v in ballast))
    lines.append(wrap(vertical, sep=sep))
    lines.append(wrap(horizontal, sep=sep))
    for c in horizontal:
        lines.append(wrap([f(v, c) / scale for v in vertical], sep=sep))
    with open(os.path.join(HERE, name), "w", newline="\r\n") as out:
        out.write("\n".join(lines) + "\n")


def cos_d(a):
    return math.cos(math.radians(a))


def sin_d(a):
    return math.sin(math.radians(a))


def lambert(i0):
    return lambda v, c: max(0.0, i0 * cos_d(v))


def write_ies():
    # {0}: a Lambertian downlight of 1000 cd, absolute photometry (lumens -1). Flux pi * 1000.
    v = steps(0, 90, 5)
    ies("axial_2019.ies", "IES:LM-63-2019",
        ["[TEST] synthetic-axial", "[TESTLAB] iblkit", "[ISSUEDATE] 2026-01-01",
         "[MANUFAC] iblkit tests", "[LUMINAIRE] Lambertian downlight, I = 1000 cos(gamma) cd"],
        "TILT=NONE", [1, -1, 1, len(v), 1, 1, 2, 0, 0, 0], [1, 1.00001, 10], v, [0], lambert(1000))
    # 0-90: I = 500 (1 + 0.5 cos 2C) over the whole sphere. Flux 4 pi 500 (trapezoid rule exact
    # on the periodic cos 2C). Relative: 12566.4 lamp lumens with a stated light output ratio
    # of 0.5, so the luminaire's lumens are 6283.2; candela multiplier 2.
    v, h = steps(0, 180, 10), steps(0, 90, 22.5)
    ies("quadrant_2002.ies", "IESNA:LM-63-2002",
        ["[TEST] synthetic-quadrant", "[TESTLAB] iblkit", "[ISSUEDATE] 2026-01-01",
         "[MANUFAC] iblkit tests", "[LUMINAIRE] I = 500 (1 + 0.5 cos 2C) cd",
         "[OTHER] light output ratio: 0.5", "[MORE] (stated so that lamp lumens x LOR = 4 pi 500)"],
        "TILT=NONE", [1, 4 * math.pi * 500 / 0.5, 2, len(v), len(h), 1, 1, 0, 0, 0], [1, 1, 20],
        v, h, lambda v, c: 500 * (1 + 0.5 * cos_d(2 * c)), scale=2)
    # 0-180: I = 200 (1 + 0.8 cos C) cos(gamma) downwards; ballast-lamp photometric factor 0.5
    # (multiplies in 1995 files). Flux pi 200 (within h^2 / 4 for the cos(gamma) chords).
    v, h = steps(0, 90, 5), steps(0, 180, 30)
    ies("plane_c0c180_1995.ies", "IESNA:LM-63-1995",
        ["[TEST] synthetic-bilateral", "[MANUFAC] iblkit tests",
         "[LUMINAIRE] I = 200 (1 + 0.8 cos C) cos(gamma) cd"],
        "TILT=NONE", [1, -1, 1, len(v), len(h), 1, 2, 0, 0, 0], [1, 0.5, 30],
        v, h, lambda v, c: max(0.0, 200 * (1 + 0.8 * cos_d(c)) * cos_d(v)), scale=0.5)
    # 90-270: I = 300 (1 + 0.5 sin C), symmetric to the C90-C270 plane; commas between values;
    # TILT=INCLUDE. Flux 4 pi 300.
    v, h = steps(0, 180, 15), steps(90, 270, 45)
    tilt = "TILT=INCLUDE\n1\n3\n0 45 90\n1 0.95 0.9"
    ies("plane_c90c270_1991.ies", "IESNA91",
        ["[TEST] synthetic-c90c270", "[MANUFAC] iblkit tests",
         "[LUMINAIRE] I = 300 (1 + 0.5 sin C) cd"],
        tilt, [1, -1, 1, len(v), len(h), 1, 2, 0, 0, 0], [1, 1, 40],
        v, h, lambda v, c: 300 * (1 + 0.5 * sin_d(c)), sep=",")
    # 0-315 (no symmetry, the turn closed periodically): a 1986 file (no identification line,
    # free-text header). I = 100 (1 + 0.3 cos C + 0.2 sin 2C). Flux 4 pi 100. Relative photometry,
    # lamp lumens 2000, no light output ratio stated.
    v, h = steps(0, 180, 30), steps(0, 315, 45)
    ies("full_1986.ies", None,
        ["iblkit synthetic test luminaire", "no symmetry: I = 100 (1 + 0.3 cos C + 0.2 sin 2C) cd"],
        "TILT=NONE", [2, 1000, 1, len(v), len(h), 1, 2, 0, 0, 0], [1, 1, 50],
        v, h, lambda v, c: 100 * (1 + 0.3 * cos_d(c) + 0.2 * sin_d(2 * c)))


def ldt(name, isym, nc, dc, gammas, f, lamp_sets, lor, dff, comma=False):
    """`f(gamma_deg, c_deg)` in cd/klm; the stored planes follow Isym."""
    c_angles = [k * dc for k in range(nc)]
    stored = {
        0: c_angles,
        1: [0.0],
        2: c_angles[: nc // 2 + 1],
        3: c_angles[nc // 4: 3 * nc // 4 + 1],
        4: c_angles[: nc // 4 + 1],
    }[isym]
    num = (lambda x: g(x).replace(".", ",")) if comma else g
    lines = ["iblkit tests / synthetic / EULUMDAT", "1" if isym == 1 else "3", str(isym), str(nc),
             num(dc), str(len(gammas)), num(gammas[1] - gammas[0]), "report-" + name,
             "synthetic " + name, "number-1", name[:8], "2026-01-01 iblkit",
             "100", "100", "50", "80", "80", "0", "0", "0", "0", num(dff), num(lor), "1", "0",
             str(len(lamp_sets))]
    for lamps, lumens in lamp_sets:
        lines += [str(lamps), "synthetic lamp", num(lumens), "3000K", "1B", "10"]
    lines += [num(0.5)] * 10
    lines += [num(c) for c in c_angles] + [num(a) for a in gammas]
    lines += [num(f(a, c)) for c in stored for a in gammas]
    with open(os.path.join(HERE, name), "w", newline="\r\n") as out:
        out.write("\n".join(lines) + "\n")


def write_ldt():
    # Isym 1: Lambertian, I0 = 1000 / pi cd/klm, one 2000 lm lamp, LORL 100 %: the table
    # (cd = value x 2) integrates to pi 2000 / pi = 2000 lm (within h^2 / 4), all of it downwards.
    ldt("isym1_lambertian.ldt", 1, 24, 15, steps(0, 90, 5),
        lambda v, c: max(0.0, 1000 / math.pi * cos_d(v)), [(1, 2000)], 100, 100)
    # Isym 2, decimal commas: I = 50 (1 + 0.5 cos C) cd/klm over the sphere, lamps 1000 lm:
    # flux 4 pi 50 = 628.319 lm, LORL 62.8319 %, half of it downwards.
    ldt("isym2_comma.ldt", 2, 12, 30, steps(0, 180, 30),
        lambda v, c: 50 * (1 + 0.5 * cos_d(c)), [(1, 1000)], 4 * math.pi * 50 / 10, 50, comma=True)
    # Isym 3: I = 40 (1 + 0.5 sin C) cd/klm, two lamp sets (the first, 3000 lm, scales): flux
    # 4 pi 40 x 3 = 1507.96 lm, LORL 50.2655 %.
    ldt("isym3.ldt", 3, 8, 45, steps(0, 180, 45),
        lambda v, c: 40 * (1 + 0.5 * sin_d(c)), [(2, 3000), (1, 1500)], 4 * math.pi * 40 * 3 / 30,
        50)
    # Isym 4: I = 60 (1 + 0.4 cos 2C) cd/klm downwards only (gamma 0..90), lamps 500 lm:
    # flux 2 pi 60 x 0.5 = 188.496 lm, LORL 37.6991 %, all downwards.
    ldt("isym4.ldt", 4, 16, 22.5, steps(0, 90, 10),
        lambda v, c: 60 * (1 + 0.4 * cos_d(2 * c)), [(1, 500)], 2 * math.pi * 60 * 0.5 / 5, 100)
    # Isym 0: I = 70 (1 + 0.3 cos C + 0.2 sin 2C) cd/klm, 6 planes 0..300 closed periodically,
    # lamps 1000 lm (absolute-photometry style: -1 lamps): flux 4 pi 70 = 879.646 lm.
    ldt("isym0.ldt", 0, 6, 60, steps(0, 180, 30),
        lambda v, c: 70 * (1 + 0.3 * cos_d(c) + 0.2 * sin_d(2 * c)), [(-1, 1000)],
        4 * math.pi * 70 / 10, 50)


if __name__ == "__main__":
    write_ies()
    write_ldt()
