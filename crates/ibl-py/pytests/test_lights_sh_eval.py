"""Light extraction, SH and metrics against the CLI's files and against closed forms."""

import json

import numpy as np
import pytest

import iblkit
from conftest import read_json

METHODS = iblkit.names()["methods"]


def constant_probe(value=1.0, width=128):
    return np.full((width // 2, width, 3), value, dtype=np.float32)


@pytest.mark.parametrize("method", METHODS)
def test_every_method_makes_lights_that_keep_the_power(sky, method):
    probe = iblkit.read_image(sky)
    lights = iblkit.extract_lights(probe, 8, method=method, seed=3)
    assert len(lights) == 8
    assert lights.directions.shape == (8, 3)
    np.testing.assert_allclose(np.linalg.norm(lights.directions, axis=1), 1.0, atol=1e-9)
    np.testing.assert_allclose(
        lights.irradiance, lights.radiance * lights.solid_angles[:, None], rtol=1e-5
    )
    if method in ("median-cut", "adaptive-median-cut", "variance-minimization", "lightgen"):
        # The region methods give every texel's power to one light: the sum is the probe's
        # power (sum L dOmega) up to f64 summation order.
        power = np.asarray(iblkit.info(sky)["power"])
        np.testing.assert_allclose(lights.total_power, power, rtol=1e-9)
        # Their shadows are sized by each light's measured spread, never wider than its region.
        shadow = lights.shadow_solid_angles
        assert np.all(shadow >= 0.0) and np.all(shadow <= lights.solid_angles)
        # The sky's sun: its light spreads over far less than its region.
        sun = int(np.argmax(lights.irradiance.sum(axis=1)))
        assert shadow[sun] < 0.5 * lights.solid_angles[sun]
        # Most of the sun's light is in that core; the rest is sky spread over its region.
        core = lights.shadow_core_fractions
        assert np.all((core >= 0.0) & (core <= 1.0))
        assert core[sun] > 0.5


def test_lights_equal_the_cli_file(tmp_path, sky, ibl):
    out = tmp_path / "cli.json"
    ibl("lights", sky, "-n", "16", "-o", out)
    cli = iblkit.read_lights(out)
    ours = iblkit.extract_lights(iblkit.read_image(sky), 16)
    # The file holds the set to the last digit but directions are renormalised on reading
    # (read_light_set): one unit in the last place at most.
    np.testing.assert_allclose(ours.directions, cli.directions, rtol=0, atol=1e-15)
    np.testing.assert_allclose(ours.irradiance, cli.irradiance, rtol=1e-15)
    # The job itself writes the same bytes as the command.
    job = tmp_path / "job.json"
    iblkit.lights_job(sky, 16, [job])
    assert job.read_bytes() == out.read_bytes()


@pytest.mark.parametrize("ext", ["json", "gltf", "glb", "xml", "pbrt"])
def test_light_files_in_every_format_equal_the_cli(tmp_path, sky, ibl, ext):
    ours, cli = tmp_path / f"ours.{ext}", tmp_path / f"cli.{ext}"
    iblkit.lights_job(sky, 4, [ours])
    ibl("lights", sky, "-n", "4", "-o", cli)
    assert ours.read_bytes() == cli.read_bytes()
    # A set extracted from an array writes the same lights, without the probe's name and hash.
    memory = tmp_path / f"memory.{ext}"
    iblkit.extract_lights(iblkit.read_image(sky), 4).write(memory)
    assert memory.stat().st_size > 0


def test_sh_equals_the_cli(tmp_path, sky, ibl):
    probe = iblkit.read_image(sky)
    sh = iblkit.sh_project(probe, bands=3)
    out = tmp_path / "sh.json"
    ibl("sh", sky, "--format", "json", "-o", out)
    np.testing.assert_array_equal(sh, np.asarray(read_json(out)["coefficients"]))
    for fmt in ("threejs", "filament", "unity", "webxr", "arkit", "gltf-ext"):
        text = ibl("sh", sky, "--format", fmt).stdout
        ours = iblkit.sh_to_format(sh, fmt)
        assert ours.strip() == text.strip(), fmt
        np.testing.assert_allclose(iblkit.sh_from_format(ours, fmt), sh, rtol=1e-6, atol=1e-9)


def test_constant_probe_has_irradiance_pi():
    """A uniform radiance of 1 gives E = pi on every normal (closed form)."""
    probe = constant_probe()
    normals = iblkit.fibonacci_normals(100)
    truth = iblkit.ground_truth_irradiance(probe, normals)
    # Texel-centre quadrature of the clamped cosine on a 128 x 64 lat-long: under 0.2 %.
    np.testing.assert_allclose(truth, np.pi, rtol=2e-3)
    sh = iblkit.sh_project(probe, bands=3)
    # Band 0 alone: exact up to the quadrature of the projection (1e-6).
    np.testing.assert_allclose(iblkit.sh_irradiance(sh, normals), np.pi, rtol=1e-5)
    emap = iblkit.irradiance_map(probe, width=32)
    np.testing.assert_allclose(emap, np.pi, rtol=2e-3)


def test_evaluate_lights_is_the_metric_of_the_two_irradiances(sky):
    probe = iblkit.read_image(sky)
    lights = iblkit.extract_lights(probe, 16)
    scores = iblkit.evaluate_lights(probe, lights, normals=500)
    normals = iblkit.fibonacci_normals(500)
    again = iblkit.irradiance_error(
        iblkit.ground_truth_irradiance(probe, normals), lights.irradiance_at(normals)
    )
    for key, value in again.items():
        assert scores[key] == pytest.approx(value, rel=1e-12)
    # Madsen & Laursen 2006, Fig. 7: 16 median-cut lights stay within a few per cent on a sky.
    assert 0 < scores["mean_err_pct"] < 10


def test_compare_images_of_an_image_with_itself(sky):
    image = iblkit.read_image(sky)[96:160, 192:320]
    d = iblkit.compare_images(image, image)
    assert d["rmse"] == 0 and d["flip_mean"] == 0 and d["pixels"] == 64 * 128
    brighter = image * 2
    d = iblkit.compare_images(brighter, image)
    # Twice the reference everywhere: RMSE is the reference's own RMS value (closed form).
    assert d["rmse"] == pytest.approx(float(np.sqrt(np.mean(image.astype(np.float64) ** 2))), rel=1e-6)
    assert d["flip_mean"] > 0


def test_light_set_json_round_trips(tmp_path, sky):
    lights = iblkit.extract_lights(iblkit.read_image(sky), 8)
    text = lights.to_json()
    assert json.loads(text)["format"].startswith("iblkit.lights")
    path = tmp_path / "l.json"
    path.write_text(text)
    np.testing.assert_allclose(iblkit.read_lights(path).directions, lights.directions, atol=1e-12)


def test_fitted_lights_share_the_hemispheres_unless_asked_for_the_paper_fit(sky):
    # Irradiance optimisation fits the lights above and below the horizon apart by default (as
    # `ibl lights` does, for renders over a ground); fit_domain="sphere" is the paper's fit.
    probe = iblkit.read_image(sky)
    apart = iblkit.extract_lights(probe, 8, method="irradiance-optimization")
    whole = iblkit.extract_lights(probe, 8, method="irradiance-optimization", fit_domain="sphere")
    assert len(apart) == len(whole) == 8
    # The sky probe holds 86 % of its power above the horizon: 7 of 8 lights go there.
    assert int(np.sum(apart.directions[:, 1] > 0.0)) == 7
    assert not np.allclose(apart.directions, whole.directions)
    with pytest.raises(iblkit.BadInputError, match="fit domain"):
        iblkit.extract_lights(probe, 8, method="irradiance-optimization", fit_domain="ground")
