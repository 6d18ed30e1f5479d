#!/usr/bin/env python3
"""Error against time: `ibl render --mode reference` against Mitsuba 3's LLVM variant on the same
scene (BENCHMARKS.md, "Reference renderer against Mitsuba 3").

Converts an iblkit scene with a panorama background and a pinhole camera (the bundled
`assets/scenes/bunny-*.toml`) into the equivalent Mitsuba scene: the probe as an `envmap`
(Mitsuba 3.9 interpolates it bilinearly where iblkit takes the nearest texel; each renderer is
judged against its own reference, so this changes the answer a little, not the noise; turned to iblkit's lat-long layout, CONVENTIONS section 2; the turn is checked against
iblkit's own background before anything is timed), the diffuse ground rectangle and the bunny
(read from its GLB, placed with the scene's scale, yaw and translation), the same pinhole camera
(box pixel filter) and a `path` integrator of the same depth (iblkit's surface vertices + 1). Each
renderer is then run at several sample counts and scored by relative MSE,
mean((a - b)^2 / (b^2 + 0.01)), against its own high-sample render (so each is judged on its own
noise, not on the small differences between the two renderers' models), with its wall time. For
iblkit the image is the render with the objects (`--layers`, `OUT-with.exr`); its time is the
render's own (`seconds_render` of `--json`), which includes the differential second pass of the
paths that touched the bunny. Mitsuba's time is `mi.render` after one warm-up render of the same
size (the LLVM kernels are then cached), plus the same figure with compilation for the record.
Each timed render runs `--repeat` times (3), the two renderers alternating, and the least time
is kept: other work on a shared machine only ever slows a run down. `--adaptive-sampling` also
times iblkit with its adaptive sampling (the same mean samples per pixel, spent where the pilot
pass finds noise; docs/RENDERING.md), in two more columns. `--regions` adds a table of each
renderer's error split between the objects' pixels (where iblkit's reference covers any) and
the rest, which says where one renderer trails the other.

Needs: `pip install mitsuba numpy` (3.9) and a system libLLVM (`apt-get install libllvm15`), and
a release build of `ibl` (`cargo build --release`). Usage:

    python3 benches/mitsuba_compare.py assets/scenes/bunny-sky.toml --width 160 \
        --spp 4 16 64 256 --reference-spp 4096

Prints a Markdown table. Not part of CI.
"""

import argparse
import json
import math
import os
import struct
import subprocess
import sys
import tempfile
import time
import tomllib

import numpy as np

import mitsuba as mi

mi.set_variant("llvm_ad_rgb")

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
IBL = os.path.join(ROOT, "target", "release", "ibl")


def read_glb(path):
    """Positions, normals and triangle indices of the first mesh primitive of a GLB."""
    data = open(path, "rb").read()
    json_len = struct.unpack("<I", data[12:16])[0]
    doc = json.loads(data[20 : 20 + json_len])
    binary = data[20 + json_len + 8 :]
    prim = doc["meshes"][0]["primitives"][0]

    def accessor(index, dtype, width):
        acc = doc["accessors"][index]
        view = doc["bufferViews"][acc["bufferView"]]
        start = view.get("byteOffset", 0) + acc.get("byteOffset", 0)
        count = acc["count"] * {"SCALAR": 1, "VEC3": 3}[acc["type"]]
        return np.frombuffer(binary, dtype=dtype, count=count, offset=start).reshape(-1, width)

    positions = accessor(prim["attributes"]["POSITION"], np.float32, 3)
    normals = accessor(prim["attributes"]["NORMAL"], np.float32, 3)
    itype = {5125: np.uint32, 5123: np.uint16}[doc["accessors"][prim["indices"]]["componentType"]]
    indices = accessor(prim["indices"], itype, 3).astype(np.uint32)
    return positions, normals, indices


def yaw_pitch_roll(deg):
    """R = Ry(yaw) Rx(pitch) Rz(roll) (docs/SCENES.md)."""
    y, p, r = (math.radians(a) for a in deg)
    ry = np.array([[math.cos(y), 0, math.sin(y)], [0, 1, 0], [-math.sin(y), 0, math.cos(y)]])
    rx = np.array([[1, 0, 0], [0, math.cos(p), -math.sin(p)], [0, math.sin(p), math.cos(p)]])
    rz = np.array([[math.cos(r), -math.sin(r), 0], [math.sin(r), math.cos(r), 0], [0, 0, 1]])
    return ry @ rx @ rz


def write_obj(path, positions, normals, indices):
    with open(path, "w") as f:
        for p in positions:
            f.write(f"v {p[0]:.9g} {p[1]:.9g} {p[2]:.9g}\n")
        for n in normals:
            f.write(f"vn {n[0]:.9g} {n[1]:.9g} {n[2]:.9g}\n")
        for t in indices + 1:
            f.write(f"f {t[0]}//{t[0]} {t[1]}//{t[1]} {t[2]}//{t[2]}\n")


def mitsuba_scene(scene_path, width, height, workdir, envmap_turn_deg):
    folder = os.path.dirname(os.path.abspath(scene_path))
    scene = tomllib.load(open(scene_path, "rb"))
    cam = scene["camera"]
    shapes = {}
    for k, obj in enumerate(scene.get("local", []) + scene.get("object", [])):
        if obj["shape"] == "plane":
            # A rectangle of size (a, b) at `center`, normal +Y (the examples' ground).
            a, b = obj["size"]
            c = obj.get("center", [0, 0, 0])
            to_world = (
                mi.ScalarTransform4f()
                .translate(c)
                .rotate([1, 0, 0], -90)
                .scale([a / 2, b / 2, 1])
            )
            albedo = obj.get("albedo", [0.8, 0.8, 0.8])
        elif obj["shape"] == "mesh":
            positions, normals, indices = read_glb(os.path.join(folder, obj["file"]))
            s = obj.get("scale", 1.0)
            s = np.array(s if isinstance(s, list) else [s, s, s], dtype=np.float64)
            rot = yaw_pitch_roll(obj.get("rotate_deg", [0, 0, 0]))
            t = np.array(obj.get("translate", [0, 0, 0]))
            world = (rot @ (positions * s).T).T + t
            wn = (rot @ (normals / s).T).T
            wn /= np.linalg.norm(wn, axis=1, keepdims=True)
            obj_path = os.path.join(workdir, f"mesh{k}.obj")
            write_obj(obj_path, world, wn, indices)
            to_world = mi.ScalarTransform4f()
            albedo = obj.get("material", {}).get("albedo", obj.get("albedo", [0.8, 0.8, 0.8]))
        else:
            sys.exit(f"shape {obj['shape']} is not converted")
        shape = {
            "type": "rectangle" if obj["shape"] == "plane" else "obj",
            "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": albedo}},
        }
        if obj["shape"] == "plane":
            shape["to_world"] = to_world
        else:
            shape["filename"] = obj_path
            shape["face_normals"] = False
        shapes[f"shape{k}"] = shape
    probe = os.path.join(folder, scene["probe"]["file"])
    yaw, pitch, roll = scene["probe"].get("rotation_deg", [0, 0, 0])
    bounces = scene.get("render", {}).get("bounces", 4)
    return {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": bounces + 1},
        "sensor": {
            "type": "perspective",
            "fov_axis": "y",
            "fov": cam["vertical_fov_deg"],
            "to_world": mi.ScalarTransform4f().look_at(
                origin=cam["position"], target=cam["look_at"], up=cam.get("up", [0, 1, 0])
            ),
            "film": {
                "type": "hdrfilm",
                "width": width,
                "height": height,
                "rfilter": {"type": "box"},
                "pixel_format": "rgb",
            },
            "sampler": {"type": "independent", "sample_count": 1},
        },
        "emitter": {
            "type": "envmap",
            "filename": probe,
            "scale": scene["probe"].get("radiance_scale", 1.0),
            "to_world": mi.ScalarTransform4f()
            .rotate([0, 1, 0], yaw + envmap_turn_deg)
            .rotate([1, 0, 0], pitch)
            .rotate([0, 0, 1], roll),
        },
        **shapes,
    }


def view_size(scene_path, width):
    """The image size of the scene's camera view at `width` pixels across (its aspect kept)."""
    w0, h0 = tomllib.load(open(scene_path, "rb"))["camera"]["image_size_px"]
    return width, round(width * h0 / w0)


def relative_error_per_pixel(a, b):
    """`(a - b)^2 / (b^2 + 0.01)`, the channels' mean, per pixel."""
    return np.mean((a - b) ** 2 / (b * b + 0.01), axis=2)


def relative_mse(a, b):
    return float(np.mean(relative_error_per_pixel(a, b)))


def relative_mse_by_region(a, b, mask):
    """The shares of `relative_mse(a, b)` from the pixels in `mask` and from the others (they
    add up to it)."""
    per_pixel = relative_error_per_pixel(a, b)
    return (float(per_pixel[mask].sum() / per_pixel.size),
            float(per_pixel[~mask].sum() / per_pixel.size))


def run_ibl(scene, width, spp, out, seed=1, extra=()):
    cmd = [IBL, "render", scene, "-o", out, "--width", str(width), "--spp", str(spp),
           "--seed", str(seed), "--layers", "--json", *extra]
    result = subprocess.run(cmd, check=True, capture_output=True, text=True)
    summary = json.loads(result.stdout)
    with_path = out.replace(".exr", "-with.exr")
    return np.array(mi.Bitmap(with_path))[:, :, :3].astype(np.float64), summary["seconds_render"]


def run_mitsuba(scene, spp, seed=1):
    started = time.perf_counter()
    image = mi.render(scene, spp=spp, seed=seed)
    image = np.array(image)
    return image.astype(np.float64), time.perf_counter() - started


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene")
    parser.add_argument("--width", type=int, default=160)
    parser.add_argument("--spp", type=int, nargs="+", default=[4, 16, 64, 256])
    parser.add_argument("--reference-spp", type=int, default=4096)
    parser.add_argument("--mitsuba-sampler", default="independent")
    parser.add_argument("--adaptive-sampling", action="store_true",
                        help="also time iblkit with --adaptive-sampling (two more columns; its "
                             "reference stays uniform)")
    parser.add_argument("--regions", action="store_true",
                        help="also print each renderer's error split between the objects' pixels "
                             "(where iblkit's reference covers any) and the rest")
    parser.add_argument("--repeat", type=int, default=3,
                        help="time each render this many times, alternating, and keep the least")
    args = parser.parse_args()
    width, height = view_size(args.scene, args.width)
    work = tempfile.mkdtemp(prefix="iblkit-mitsuba-")

    # The envmap's turn: the one whose view of the bare probe matches iblkit's background.
    bare = os.path.join(work, "bare.toml")
    with open(bare, "w") as f:
        text = open(args.scene).read()
        folder = os.path.dirname(os.path.abspath(args.scene))
        f.write(text.split("[[local]]")[0].replace('file = "', f'file = "{folder}/'))
    ours, _ = run_ibl(bare, width, 1, os.path.join(work, "bare.exr"))
    best = None
    for turn in (0.0, 90.0, 180.0, 270.0):
        s = mi.load_dict(mitsuba_scene(bare, width, height, work, turn))
        img, _ = run_mitsuba(s, 64)
        err = relative_mse(img, ours)
        if best is None or err < best[1]:
            best = (turn, err)
    turn, err = best
    print(f"envmap turn {turn} degrees (relative MSE of the bare views {err:.2e})", file=sys.stderr)

    scene_dict = mitsuba_scene(args.scene, width, height, work, turn)
    scene_dict["sensor"]["sampler"] = {"type": args.mitsuba_sampler, "sample_count": 1}
    scene = mi.load_dict(scene_dict)
    ref_ours, t_ref_ours = run_ibl(args.scene, width, args.reference_spp,
                                   os.path.join(work, "ref.exr"), seed=99)
    run_mitsuba(scene, args.reference_spp, seed=98)
    ref_mi, t_ref_mi = run_mitsuba(scene, args.reference_spp, seed=99)
    print(f"references: iblkit {t_ref_ours:.1f} s, Mitsuba {t_ref_mi:.1f} s; they differ by "
          f"relative MSE {relative_mse(ref_ours, ref_mi):.2e}", file=sys.stderr)
    adaptive = " iblkit adaptive s | iblkit adaptive relative MSE |" if args.adaptive_sampling else ""
    print(f"| spp | iblkit s | iblkit relative MSE |{adaptive} Mitsuba ({args.mitsuba_sampler}) s "
          f"(with JIT) | Mitsuba relative MSE |")
    print("|---:|---:|---:|" + ("---:|---:|" if args.adaptive_sampling else "") + "---:|---:|")
    regions = []
    if args.regions:
        alpha = np.array(mi.Bitmap(os.path.join(work, "ref-alpha.png")), dtype=np.float64)
        mask = (alpha if alpha.ndim == 2 else alpha[:, :, 0]) > 0
    for spp in args.spp:
        cold_start = time.perf_counter()
        run_mitsuba(scene, spp, seed=7)
        cold = time.perf_counter() - cold_start
        # The same render again and again, the two renderers alternating: a shared machine's
        # other work slows a run, never speeds it up, so the least time is the render's own.
        times, atimes, mtimes = [], [], []
        for _ in range(max(1, args.repeat)):
            img, t = run_ibl(args.scene, width, spp, os.path.join(work, f"o{spp}.exr"))
            times.append(t)
            if args.adaptive_sampling:
                aimg, at = run_ibl(args.scene, width, spp, os.path.join(work, f"a{spp}.exr"),
                                   extra=["--adaptive-sampling"])
                atimes.append(at)
            mimg, mt = run_mitsuba(scene, spp, seed=1)
            mtimes.append(mt)
        t, mt = min(times), min(mtimes)
        adaptive = (f" {min(atimes):.2f} | {relative_mse(aimg, ref_ours):.2e} |"
                    if args.adaptive_sampling else "")
        if args.regions:
            regions.append((spp, relative_mse_by_region(img, ref_ours, mask),
                            relative_mse_by_region(mimg, ref_mi, mask), mask.mean()))
        print(f"| {spp} | {t:.2f} | {relative_mse(img, ref_ours):.2e} |{adaptive} {mt:.2f} "
              f"({cold:.2f}) | {relative_mse(mimg, ref_mi):.2e} |")
    if regions:
        print(f"\nThe errors' shares: the objects' pixels ({100 * regions[0][3]:.1f} % of the "
              "image) and the rest\n")
        print("| spp | iblkit objects | iblkit rest | Mitsuba objects | Mitsuba rest |")
        print("|---:|---:|---:|---:|---:|")
        for spp, (io, ir), (mo, mr), _ in regions:
            print(f"| {spp} | {io:.2e} | {ir:.2e} | {mo:.2e} | {mr:.2e} |")


if __name__ == "__main__":
    main()
