"""iblkit: image-based lighting for augmented reality, from Python.

The same library the ``ibl`` command line tool runs, with numpy arrays in and out:

- images are ``float32`` arrays of shape ``(H, W, 3)``, linear radiance, row 0 at the top;
- directions are in iblkit's world frame (+Y up, -Z forward, +X right; docs/CONVENTIONS.md);
- errors are :class:`BadInputError` (a ``ValueError``-like: your file or argument) or
  :class:`InternalError` (ours), both :class:`IblError`;
- long calls release the GIL, so threads run them in parallel, and take an optional
  ``progress(label, done, total)`` callable.

Example::

    import iblkit
    probe, found = iblkit.read_probe("assets/probes/sky.exr")     # any mapping -> lat-long
    lights = iblkit.extract_lights(probe, 16, method="median-cut")
    print(lights.directions.shape, lights.irradiance.sum(axis=0))
    sh9 = iblkit.sh_project(probe, bands=3)                        # (9, 3) radiance
    print(iblkit.sh_to_format(sh9, "filament"))
    score = iblkit.evaluate_lights(probe, lights, normals=2000)    # mean_err_pct, ...

Batches over folders of probes: ``python -m iblkit.batch SPEC.toml`` (Dask) or
``ibl batch SPEC.toml``; see :mod:`iblkit.batch`.
"""

from ._native import (
    BadInputError,
    IblError,
    InternalError,
    LightSet,
    __version__,
    batch_finish,
    batch_plan,
    batch_run_item,
    compare_images,
    convert,
    detect_mapping,
    dfg_table,
    evaluate_lights,
    extract_lights,
    fibonacci_normals,
    ground_truth_irradiance,
    info,
    irradiance_error,
    irradiance_map,
    lights_job,
    names,
    prefilter,
    read_image,
    read_lights,
    read_probe,
    render_scene,
    run_batch,
    sh_from_format,
    sh_irradiance,
    sh_project,
    sh_to_format,
    write_image,
)

__all__ = [
    "BadInputError",
    "IblError",
    "InternalError",
    "LightSet",
    "__version__",
    "batch_finish",
    "batch_plan",
    "batch_run_item",
    "compare_images",
    "convert",
    "detect_mapping",
    "dfg_table",
    "evaluate_lights",
    "extract_lights",
    "fibonacci_normals",
    "ground_truth_irradiance",
    "info",
    "irradiance_error",
    "irradiance_map",
    "lights_job",
    "names",
    "prefilter",
    "read_image",
    "read_lights",
    "read_probe",
    "render_scene",
    "run_batch",
    "sh_from_format",
    "sh_irradiance",
    "sh_project",
    "sh_to_format",
    "write_image",
]
