"""The backend follows the installed FURY; without one the kit says, in one paragraph, what to install."""

from __future__ import annotations

import importlib.metadata

import pytest

from conformance import backends
from conformance.errors import BackendError


@pytest.fixture
def installed(monkeypatch):
    """Pretend the given FURY version is installed (None: none is)."""
    real = importlib.metadata.version

    def pretend(version):
        def lookup(dist):
            if dist != "fury":
                return real(dist)
            if version is None:
                raise importlib.metadata.PackageNotFoundError(dist)
            return version

        monkeypatch.setattr(importlib.metadata, "version", lookup)
        backends.fury_version.cache_clear()

    yield pretend
    monkeypatch.undo()
    backends.fury_version.cache_clear()


@pytest.mark.parametrize("version, name", [("0.12.0", "vtk"), ("2.0.0", "pygfx"), ("2.1.0", "pygfx")])
def test_the_backend_follows_the_installed_fury(installed, version, name):
    installed(version)
    assert backends.NAME == name and backends.describe().startswith(f"backend {name} (FURY {version}: ")


@pytest.mark.parametrize("version, message", [
    (None, r"FURY is not installed, .*\[fury012\]'` for FURY 0\.12 \(VTK\), or `\[fury2\]` for FURY 2"),
    ("1.0.0", r"FURY 1\.0\.0 is installed, but the kit has backends for FURY 0\.12 \(VTK\) and FURY 2\.x"),
])
def test_no_backend_is_one_clear_paragraph(installed, version, message):
    installed(version)
    with pytest.raises(BackendError, match=message) as raised:
        backends.NAME
    assert "\n" not in str(raised.value)
