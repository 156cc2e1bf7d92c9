"""The Python wire types as a package: ``pip install crates/primm-wire/python`` in a fresh virtual
environment, offline, then ``examples/python/subscriber.py --help`` from another directory."""

from __future__ import annotations

import os
import re
import subprocess
import sys
import venv
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "crates" / "primm-wire" / "python"


def workspace_version() -> str:
    text = (ROOT / "Cargo.toml").read_text()
    section = text.split("[workspace.package]", 1)[1]
    return re.search(r'^version = "([^"]+)"$', section, re.MULTILINE).group(1)


def test_a_fresh_venv_installs_the_package_offline_and_the_example_imports_it_from_anywhere(tmp_path):
    environment = tmp_path / "venv"
    venv.create(environment, with_pip=True)
    python = environment / "bin" / "python"
    # Nothing comes from an index: the package has no dependency and builds with the standard
    # library alone (its own build backend).
    install = subprocess.run(
        [str(python), "-m", "pip", "install", "--no-index", "--no-deps", "--disable-pip-version-check", str(PACKAGE)],
        capture_output=True,
        text=True,
        check=False,
        env={**os.environ, "PIP_NO_INDEX": "1", "PIP_FIND_LINKS": ""},
    )
    assert install.returncode == 0, install.stdout + install.stderr

    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    # A clean environment: no PYTHONPATH leads to the checkout.
    env = {key: value for key, value in os.environ.items() if key != "PYTHONPATH"}
    probe = subprocess.run(
        [
            str(python),
            "-c",
            "import ctypes, importlib.metadata, primm_wire; "
            "print(primm_wire.__file__); print(ctypes.sizeof(primm_wire.TrackFrame)); "
            "print(importlib.metadata.version('primm-wire'))",
        ],
        cwd=elsewhere,
        capture_output=True,
        text=True,
        check=False,
        env=env,
    )
    assert probe.returncode == 0, probe.stderr
    location, size, version = probe.stdout.split()
    assert Path(location).is_relative_to(environment), location
    assert int(size) == 217168
    assert version == workspace_version()

    subscriber = ROOT / "examples" / "python" / "subscriber.py"
    help_run = subprocess.run(
        [str(python), str(subscriber), "--help"], cwd=elsewhere, capture_output=True, text=True, check=False, env=env
    )
    assert help_run.returncode == 0, help_run.stderr
    assert "--record FILE" in help_run.stdout and "--service-prefix" in help_run.stdout
    # Without the iceoryx2 package (not installed here) it says how to get it, not a traceback.
    run = subprocess.run(
        [str(python), str(subscriber), "--frames", "1"], cwd=elsewhere, capture_output=True, text=True, check=False, env=env
    )
    assert run.returncode == 2
    assert "[subscribe]" in run.stderr and "Traceback" not in run.stderr


def test_the_example_has_no_path_tricks():
    source = (ROOT / "examples" / "python" / "subscriber.py").read_text()
    assert "sys.path" not in source
    assert "from primm_wire import" in source


def test_the_wheel_matches_the_checked_in_module(tmp_path):
    sys.path.insert(0, str(PACKAGE / "build_backend"))
    try:
        import primm_wire_build
    finally:
        sys.path.pop(0)
    name = primm_wire_build.build_wheel(str(tmp_path))
    assert name == f"primm_wire-{workspace_version()}-py3-none-any.whl"
    with zipfile.ZipFile(tmp_path / name) as wheel:
        assert wheel.read("primm_wire.py") == (PACKAGE / "primm_wire.py").read_bytes()
        metadata = wheel.read(f"primm_wire-{workspace_version()}.dist-info/METADATA").decode()
        record = wheel.read(f"primm_wire-{workspace_version()}.dist-info/RECORD").decode()
    assert 'Requires-Dist: iceoryx2==0.10.0; extra == "subscribe"' in metadata
    assert "primm_wire.py,sha256=" in record
