"""Prefiltered maps and renders against the CLI."""

import numpy as np
import pytest

import iblkit
from conftest import ROOT


def test_prefilter_of_a_constant_probe_is_constant():
    probe = np.full((64, 128, 3), 2.0, dtype=np.float32)
    maps = iblkit.prefilter(probe, face_size=32, samples=32, irradiance_face=8)
    assert len(maps["specular"]) == len(maps["roughness"])
    assert maps["specular"][0].shape == (6, 32, 32, 3)
    # GGX-weighted means of a constant are the constant (normalised weights: f32 sums, 1e-5).
    for level in maps["specular"]:
        np.testing.assert_allclose(level, 2.0, rtol=1e-5)
    # Irradiance cube holds E / pi = L for a constant probe (quadrature 0.2 %).
    np.testing.assert_allclose(maps["irradiance"], 2.0, rtol=2e-3)


def test_prefilter_roughness_follows_the_target(sky):
    probe = iblkit.read_image(sky)
    maps = iblkit.prefilter(probe, face_size=64, samples=16, target="khronos")
    r = maps["roughness"]
    assert r[0] == 0 and r[-1] == pytest.approx(1.0) and r == sorted(r)


def test_dfg_table_is_in_range():
    dfg = iblkit.dfg_table(size=16, samples=1024)
    assert dfg.shape == (16, 16, 2)
    # Scale A and bias B of F0 sum to the directional albedo, at most 1; the table's Monte Carlo
    # error at 1024 samples is under 3e-3 (docs/PREFILTER.md), so allow that much above 1.
    total = dfg.sum(axis=2)
    assert (dfg >= 0).all() and (total <= 1 + 3e-3).all()
    # A smooth mirror seen head-on reflects everything: A + B = 1 at roughness ~0, n.v ~1.
    assert total[0, -1] == pytest.approx(1.0, abs=3e-3)


def test_render_equals_the_cli(tmp_path, ibl):
    scene = ROOT / "assets" / "scenes" / "bunny-sky.toml"
    ours_path, cli_path = tmp_path / "py.exr", tmp_path / "cli.exr"
    image, summary = iblkit.render_scene(
        scene, ours_path, mode="lights", lights=4, spp=1, width=48, seed=1
    )
    ibl("render", scene, "-o", cli_path, "--mode", "lights", "-n", "4", "--spp", "1",
        "--width", "48", "--seed", "1")
    assert summary["mode"] == "lights" and summary["width"] == 48
    np.testing.assert_array_equal(image, iblkit.read_image(cli_path))
