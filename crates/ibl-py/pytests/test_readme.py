"""The README's Python example runs as written and says what its comments say (issue 19's
"ten-line Python example"), and the batch contact-sheet script the docs use works."""

import os
import re
import subprocess
import sys

from conftest import ROOT


def readme_python_blocks():
    text = (ROOT / "README.md").read_text()
    return re.findall(r"```python\n(.*?)```", text, flags=re.S)


def test_the_readme_python_example_runs_as_written(tmp_path, capsys):
    blocks = readme_python_blocks()
    assert blocks, "README.md has a ```python block"
    code = blocks[0]
    assert len(code.strip().splitlines()) <= 10, "the example is ten lines"
    # Run from a folder holding the repository's assets, so the example's relative paths hold
    # and what it writes stays out of the checkout.
    (tmp_path / "assets").symlink_to(ROOT / "assets")
    cwd = os.getcwd()
    os.chdir(tmp_path)
    try:
        exec(compile(code, "README.md", "exec"), {})
    finally:
        os.chdir(cwd)
    out = capsys.readouterr().out
    assert out.startswith("latlong (256, 512, 3) float32"), out
    assert "16 lights:" in out and "% mean irradiance error" in out, out
    assert (tmp_path / "sky-lights.gltf").is_file()
    assert (tmp_path / "sky.png").is_file()


def test_the_contact_sheet_script_tiles_a_batch(tmp_path, ibl):
    spec = tmp_path / "spec.toml"
    spec.write_text(
        f'[input]\nfiles = ["{ROOT / "assets/probes/sky.exr"}", "{ROOT / "assets/probes/night.exr"}"]\n'
        '[output]\nfolder = "out"\n[steps.lights]\nn = 4\noverlay = true\n'
    )
    ibl("batch", spec)
    sheet = tmp_path / "sheet.png"
    done = subprocess.run(
        [sys.executable, str(ROOT / "scripts/batch_contact_sheet.py"), str(tmp_path / "out"), str(sheet), "--shrink", "1"],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stderr
    assert "2 probes" in done.stdout
    import iblkit

    image = iblkit.read_image(sheet)
    lights = iblkit.read_image(tmp_path / "out" / "sky" / "lights.png")
    assert image.shape == (lights.shape[0], 2 * lights.shape[1] + 4, 3)
