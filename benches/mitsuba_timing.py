#!/usr/bin/env python3
"""Time only: `ibl render` at one sample count against Mitsuba 3's LLVM variant at another, many
times, alternating (BENCHMARKS.md, "Reference renderer against Mitsuba 3").

`mitsuba_compare.py` finds the sample counts at which the two renderers reach equal error (each
against its own reference); on a shared 2-core machine a handful of timed runs of each cannot
tell a 10 % difference in time (single runs move by 20 to 40 %). This script takes the two
counts and times them ROUNDS times each, the renderers (and any number of `ibl` binaries, to
compare builds) alternating, and prints each one's least and median time. The scene, its
conversion and the timings are `mitsuba_compare.py`'s (iblkit: `seconds_render` of `--json`
with `--layers`; Mitsuba: `mi.render` after a warm-up render of the same size).

Needs what `mitsuba_compare.py` needs. Usage:

    python3 benches/mitsuba_timing.py assets/scenes/bunny-apartment.toml --ibl-spp 32 \
        --mitsuba-spp 64 --rounds 20 [--ibl target/release/ibl OTHER_BUILD ...]

Prints a Markdown table. Not part of CI.
"""

import argparse
import os
import statistics
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import mitsuba_compare as compare  # noqa: E402  (after the path it is found on)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene")
    parser.add_argument("--width", type=int, default=160)
    parser.add_argument("--ibl-spp", type=int, required=True)
    parser.add_argument("--mitsuba-spp", type=int, required=True)
    parser.add_argument("--mitsuba-sampler", default="multijitter")
    parser.add_argument("--envmap-turn", type=float, default=180.0,
                        help="the envmap's turn in degrees (mitsuba_compare.py finds and prints "
                             "it; 180 for the bundled scenes)")
    parser.add_argument("--rounds", type=int, default=20)
    parser.add_argument("--ibl", nargs="+", default=[compare.IBL],
                        help="ibl binaries to time (default: the release build)")
    args = parser.parse_args()
    width, height = compare.view_size(args.scene, args.width)
    work = tempfile.mkdtemp(prefix="iblkit-mitsuba-timing-")
    scene_dict = compare.mitsuba_scene(args.scene, width, height, work, args.envmap_turn)
    scene_dict["sensor"]["sampler"] = {"type": args.mitsuba_sampler, "sample_count": 1}
    scene = compare.mi.load_dict(scene_dict)
    compare.run_mitsuba(scene, args.mitsuba_spp, seed=1)  # compiles the kernels
    times = {binary: [] for binary in args.ibl}
    mitsuba = []
    out = os.path.join(work, "o.exr")
    for _ in range(args.rounds):
        for binary in args.ibl:
            compare.IBL = binary
            times[binary].append(compare.run_ibl(args.scene, width, args.ibl_spp, out)[1])
        mitsuba.append(compare.run_mitsuba(scene, args.mitsuba_spp, seed=1)[1])
    print(f"| renderer | spp | least s | median s | median / Mitsuba's |")
    print("|---|---:|---:|---:|---:|")
    reference = statistics.median(mitsuba)
    for name, values, spp in [(b, times[b], args.ibl_spp) for b in args.ibl] + [
            (f"Mitsuba ({args.mitsuba_sampler})", mitsuba, args.mitsuba_spp)]:
        median = statistics.median(values)
        print(f"| {name} | {spp} | {min(values):.3f} | {median:.3f} | {median / reference:.2f} |")


if __name__ == "__main__":
    main()
