"""Images in and out: formats, the probe loader, mappings, info, errors, GIL and progress."""

import threading

import numpy as np
import pytest

import iblkit
from conftest import PROBES


def test_read_image_gives_float32_hwc(sky):
    image = iblkit.read_image(sky)
    assert image.shape == (256, 512, 3)
    assert image.dtype == np.float32
    assert image.flags["C_CONTIGUOUS"]
    assert np.isfinite(image).all() and (image >= 0).all()


@pytest.mark.parametrize("ext", ["exr", "pfm", "hdr"])
def test_write_then_read_round_trips(tmp_path, sky, ext):
    image = iblkit.read_image(sky)
    path = tmp_path / f"copy.{ext}"
    iblkit.write_image(path, image)
    back = iblkit.read_image(path)
    assert back.shape == image.shape
    # EXR is written as 32-bit float and PFM is float: exact. Radiance RGBE keeps 8 bits of
    # mantissa per pixel: relative error under 2^-8 of the pixel's largest channel.
    if ext == "hdr":
        scale = image.max(axis=2, keepdims=True) + 1e-30
        assert (np.abs(back - image) / scale).max() < 2 ** -7
    else:
        np.testing.assert_array_equal(back, image)


def test_png_preview_uses_the_tone_curve(tmp_path, sky):
    image = iblkit.read_image(sky)
    path = tmp_path / "p.png"
    iblkit.write_image(path, image, exposure=0.0, curve="aces")
    back = iblkit.read_image(path)
    assert back.shape == image.shape and back.max() <= 1.0


def test_read_probe_converts_an_angular_map_as_the_cli_does(tmp_path, sky, ibl):
    latlong = iblkit.read_image(sky)
    angular = iblkit.convert(latlong, "latlong", "angular", width=256)
    path = tmp_path / "angular.pfm"
    iblkit.write_image(path, angular)
    probe, found = iblkit.read_probe(path)
    assert found["mapping"] == "angular" and found["mapping_source"] == "shape"
    assert found["converted_to"] == [probe.shape[1], probe.shape[0]]
    # The CLI's conversion of the same file, read back: the same pixels.
    out = tmp_path / "ll.pfm"
    ibl("convert", path, out, "--to", "latlong")
    np.testing.assert_array_equal(probe, iblkit.read_image(out))


def test_convert_conserves_power(sky):
    latlong = iblkit.read_image(sky)
    cube = iblkit.convert(latlong, "latlong", "cube-hcross", width=512)
    back = iblkit.convert(cube, "cube-hcross", "latlong", width=512)
    p0 = iblkit.sh_project(latlong, bands=1)[0]
    p1 = iblkit.sh_project(back, bands=1)[0]
    # Energy-conserving resampling both ways: the mean radiance (SH band 0) within 0.5 %
    # (supersampling at the cube's 128-pixel faces; measured 0.1 % on this probe).
    np.testing.assert_allclose(p1, p0, rtol=5e-3)


def test_detect_mapping_and_names():
    assert iblkit.detect_mapping(512, 256) == "latlong"
    assert iblkit.detect_mapping(300, 200) is None
    names = iblkit.names()
    assert "median-cut" in names["methods"] and "filament" in names["sh_formats"]


def test_info_is_the_cli_json(sky, ibl):
    import json

    cli = json.loads(ibl("info", sky, "--json").stdout)
    ours = iblkit.info(sky)
    assert ours["power"] == pytest.approx(cli["power"], rel=1e-12)
    assert ours["brightest"] == cli["brightest"]


def test_bad_input_raises_bad_input_error(tmp_path):
    with pytest.raises(iblkit.BadInputError, match="missing.exr"):
        iblkit.read_image(tmp_path / "missing.exr")
    with pytest.raises(iblkit.BadInputError, match="shape"):
        iblkit.extract_lights(np.zeros((4, 8)), 4)
    with pytest.raises(iblkit.BadInputError, match="NaN"):
        iblkit.sh_project(np.full((4, 8, 3), np.nan))
    with pytest.raises(iblkit.BadInputError, match="unknown mapping"):
        iblkit.convert(np.zeros((4, 8, 3)), "latlong", "sphere")
    bad = tmp_path / "bad.exr"
    bad.write_bytes(b"not an exr")
    with pytest.raises(iblkit.BadInputError, match="bad.exr"):
        iblkit.read_probe(bad)
    assert issubclass(iblkit.BadInputError, iblkit.IblError)
    assert issubclass(iblkit.InternalError, iblkit.IblError)


def test_long_calls_release_the_gil(sky):
    """While one thread is inside a long iblkit call, Python code in another thread runs.

    With the GIL held for the whole call the counter could not move until the call returned;
    the bound is a count, not a time.
    """
    probe = iblkit.read_image(sky)
    normals = iblkit.fibonacci_normals(20_000)
    inside = threading.Event()
    finished = threading.Event()

    def long_call():
        inside.set()
        iblkit.ground_truth_irradiance(probe, normals)
        finished.set()

    worker = threading.Thread(target=long_call)
    worker.start()
    inside.wait()
    ticks = 0
    while not finished.is_set():
        ticks += 1
    worker.join()
    assert ticks > 1_000, f"only {ticks} loop turns ran beside the call"


def test_progress_reaches_the_callable_and_its_errors_come_back(sky):
    probe = iblkit.read_image(sky)
    calls = []
    iblkit.convert(probe, "latlong", "angular", width=128, progress=lambda *a: calls.append(a))
    assert calls[0] == ("resampling", 0, 128)
    assert calls[-1] == ("resampling", 128, 128)
    assert [c[1] for c in calls] == sorted(c[1] for c in calls)

    def fail(*_):
        raise KeyError("stop")

    with pytest.raises(KeyError, match="stop"):
        iblkit.convert(probe, "latlong", "angular", width=64, progress=fail)


def test_every_public_name_has_a_stub():
    import ast
    import pathlib

    stub = pathlib.Path(iblkit.__file__).with_name("_native.pyi")
    tree = ast.parse(stub.read_text())
    stubbed = {
        n.name for n in tree.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))
    } | {t.id for n in tree.body if isinstance(n, ast.AnnAssign) for t in [n.target]}
    missing = set(iblkit.__all__) - stubbed
    assert not missing, f"names without a type stub: {sorted(missing)}"
    for name in iblkit.__all__:
        obj = getattr(iblkit, name)
        if callable(obj) and not name.endswith("Error"):
            assert obj.__doc__, f"{name} has no docstring"


def test_bundled_probes_all_read():
    for path in sorted(PROBES.glob("*.exr")):
        probe, found = iblkit.read_probe(path)
        assert probe.shape[1] == 2 * probe.shape[0], path
