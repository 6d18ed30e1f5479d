"""Print cargo configuration that gives the `dev` profile the `test` profile's settings.

maturin builds the Python wheel with `cargo rustc`, where `--profile test` would mean a test
harness; with `--profile dev` and this configuration (`--config FILE`) the wheel's build has the
same opt-levels and debug settings as the Rust tests' build before it. Cargo names an artifact
by its settings, not by its profile's name, and `dev` and `test` share `target/debug`, so the
wheel's build reuses what the tests built instead of building every dependency again (with the
feature union in `crates/ibl-py/Cargo.toml`).

Usage: python3 .ci/wheel_profile.py Cargo.toml > target/wheel-profile.toml
"""

import sys

try:
    import tomllib
except ModuleNotFoundError:  # Python before 3.11: the same parser, from requirements-test.txt
    import tomli as tomllib


def toml_value(value):
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return '"' + value + '"'
    return str(value)


def main(manifest):
    with open(manifest, "rb") as f:
        profiles = tomllib.load(f).get("profile", {})
    test, dev = profiles.get("test", {}), profiles.get("dev", {})
    lines = ["[profile.dev]"]
    lines += [f"{key} = {toml_value(v)}" for key, v in test.items() if key != "package"]
    # A package's test settings override its dev settings; dev's own per-package settings stay.
    packages = {name: dict(s) for name, s in dev.get("package", {}).items()}
    for name, settings in test.get("package", {}).items():
        packages.setdefault(name, {}).update(settings)
    for name, settings in packages.items():
        lines.append(f'[profile.dev.package."{name}"]')
        lines += [f"{key} = {toml_value(v)}" for key, v in settings.items()]
    print("\n".join(lines))


if __name__ == "__main__":
    main(sys.argv[1])
