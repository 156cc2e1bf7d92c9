"""The PEP 517 build backend of the primm-wire Python package: builds its one-module wheel with
the standard library alone, so that ``pip install crates/primm-wire/python`` needs nothing from
a package index (no setuptools, no wheel), also offline and in a fresh virtual environment.

Name, version and dependencies come from ``pyproject.toml`` beside this directory (the
``[project]`` table; read with a small parser, as ``tomllib`` is missing before Python 3.11).
"""

import base64
import hashlib
import io
import os
import re
import tarfile
import zipfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MODULE = "primm_wire.py"


def _project():
    """The name, version, summary, Python requirement and extras of ``pyproject.toml``."""
    with open(os.path.join(ROOT, "pyproject.toml"), encoding="utf-8") as file:
        text = file.read()

    def value(key):
        match = re.search(rf'^{key} = "([^"]*)"$', text, re.MULTILINE)
        if match is None:
            raise ValueError(f"pyproject.toml: no {key}")
        return match.group(1)

    extras = {}
    section = re.search(r"^\[project\.optional-dependencies\]\n(.*?)(?=^\[|\Z)", text, re.MULTILINE | re.DOTALL)
    if section:
        for name, requirements in re.findall(r"^([A-Za-z0-9_-]+) = \[(.*)\]$", section.group(1), re.MULTILINE):
            extras[name] = re.findall(r'"([^"]+)"', requirements)
    return {
        "name": value("name"),
        "version": value("version"),
        "summary": value("description"),
        "requires_python": value("requires-python"),
        "extras": extras,
    }


def _metadata(project):
    lines = [
        "Metadata-Version: 2.1",
        f"Name: {project['name']}",
        f"Version: {project['version']}",
        f"Summary: {project['summary']}",
        "License: Apache-2.0",
        f"Requires-Python: {project['requires_python']}",
    ]
    for extra, requirements in project["extras"].items():
        lines.append(f"Provides-Extra: {extra}")
        lines.extend(f'Requires-Dist: {requirement}; extra == "{extra}"' for requirement in requirements)
    with open(os.path.join(ROOT, "README.md"), encoding="utf-8") as file:
        readme = file.read()
    return "\n".join(lines) + "\nDescription-Content-Type: text/markdown\n\n" + readme


def _distribution(project):
    return project["name"].replace("-", "_")


def _write_wheel(wheel_directory, files):
    """Writes a wheel of ``files`` (archive name -> bytes) with its metadata; returns its name."""
    project = _project()
    distribution, version = _distribution(project), project["version"]
    dist_info = f"{distribution}-{version}.dist-info"
    files = dict(files)
    files[f"{dist_info}/METADATA"] = _metadata(project).encode()
    files[f"{dist_info}/WHEEL"] = (
        "Wheel-Version: 1.0\nGenerator: primm_wire_build\nRoot-Is-Purelib: true\nTag: py3-none-any\n"
    ).encode()
    record = []
    for name, data in files.items():
        digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
        record.append(f"{name},sha256={digest},{len(data)}")
    record.append(f"{dist_info}/RECORD,,")
    files[f"{dist_info}/RECORD"] = ("\n".join(record) + "\n").encode()
    wheel_name = f"{distribution}-{version}-py3-none-any.whl"
    with zipfile.ZipFile(os.path.join(wheel_directory, wheel_name), "w", zipfile.ZIP_DEFLATED) as wheel:
        for name, data in files.items():
            wheel.writestr(zipfile.ZipInfo(name, date_time=(1980, 1, 1, 0, 0, 0)), data)
    return wheel_name


def get_requires_for_build_wheel(config_settings=None):
    return []


def get_requires_for_build_editable(config_settings=None):
    return []


def get_requires_for_build_sdist(config_settings=None):
    return []


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    with open(os.path.join(ROOT, MODULE), "rb") as file:
        return _write_wheel(wheel_directory, {MODULE: file.read()})


def build_editable(wheel_directory, config_settings=None, metadata_directory=None):
    """A wheel whose ``.pth`` file puts this directory on ``sys.path``: edits take effect at once."""
    return _write_wheel(wheel_directory, {"primm_wire_editable.pth": (ROOT + "\n").encode()})


def build_sdist(sdist_directory, config_settings=None):
    project = _project()
    base = f"{_distribution(project)}-{project['version']}"
    sdist_name = f"{base}.tar.gz"
    with tarfile.open(os.path.join(sdist_directory, sdist_name), "w:gz", format=tarfile.PAX_FORMAT) as sdist:
        for name in ["pyproject.toml", "README.md", MODULE, "build_backend/primm_wire_build.py"]:
            sdist.add(os.path.join(ROOT, name), arcname=f"{base}/{name}")
        info = _metadata(project).encode()
        entry = tarfile.TarInfo(f"{base}/PKG-INFO")
        entry.size = len(info)
        sdist.addfile(entry, io.BytesIO(info))
    return sdist_name
