"""``./kit``'s set-up probes: the same answer every time, so set-up installs only what is missing.

Issue 28, point 5: ``ldconfig -p | grep -q libvulkan.so.1`` under ``set -o pipefail`` said "missing" in
3 runs of 50 with the library installed (grep exits at its first match, ldconfig then dies of SIGPIPE),
and ``./kit`` ran ``apt-get install`` (as non-root: stopped with "missing system packages").
"""

from __future__ import annotations

import os
import stat
import subprocess
from pathlib import Path

import pytest

KIT = Path(__file__).resolve().parent.parent / "kit"
LIBRARIES = ("libGL.so.1", "libXrender.so.1", "libXt.so.6", "libvulkan.so.1")


def _fake_ldconfig(directory: Path, libraries) -> None:
    """An ``ldconfig`` that lists ``libraries`` first, then twice what a pipe holds (64 KiB): a probe
    that stops reading at its match kills it with SIGPIPE every time, not 3 times in 50. (Not more:
    ``./kit`` matches each library against the whole listing, and 20,000 lines made that 0.3 s a probe.)"""
    script = directory / "ldconfig"
    listed = "".join(f"\t{name} (libc6,x86-64) => /usr/lib/x86_64-linux-gnu/{name}\\n" for name in libraries)
    script.write_text("#!/usr/bin/env bash\n"
                      f"printf '{listed}'\n"
                      "for i in $(seq 2000); do echo \"\tlibfiller$i.so.1 (libc6,x86-64) => /usr/lib/libfiller$i.so.1\"; done\n")
    script.chmod(script.stat().st_mode | stat.S_IEXEC)


def _missing(tmp_path: Path, backend: str) -> list[str]:
    env = {**os.environ, "PATH": f"{tmp_path}{os.pathsep}{os.environ['PATH']}"}
    done = subprocess.run([str(KIT), "missing", "--backend", backend], env=env, capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    return done.stdout.split()


@pytest.mark.fury_free("its verdict cannot depend on the FURY: the kit's bash script, its probes faked")
@pytest.mark.parametrize("backend", ["vtk", "pygfx"])
def test_a_library_listed_is_found_every_time(tmp_path, backend):
    """With every library listed, the library probes find each one on every try (20 tries)."""
    _fake_ldconfig(tmp_path, LIBRARIES)
    answers = [_missing(tmp_path, backend) for _ in range(20)]
    libraries = {"libgl1", "libgl1-mesa-dri", "libxrender1", "libxt6", "libvulkan1"}
    assert all(not (set(a) & libraries) for a in answers), f"libraries said missing although listed: {answers}"
    assert all(a == answers[0] for a in answers), f"different answers: {answers}"


@pytest.mark.fury_free("its verdict cannot depend on the FURY: the kit's bash script, its probes faked")
def test_a_library_not_listed_is_missing(tmp_path):
    """The probe can fail: a library ldconfig does not list is named for installation."""
    _fake_ldconfig(tmp_path, [name for name in LIBRARIES if name != "libvulkan.so.1"])
    assert "libvulkan1" in _missing(tmp_path, "pygfx")
    _fake_ldconfig(tmp_path, [name for name in LIBRARIES if name != "libXt.so.6"])
    assert "libxt6" in _missing(tmp_path, "vtk")


def _fake_python3(directory: Path, fury: str | None) -> None:
    """A ``python3`` whose installed FURY is ``fury`` (None: none); anything else goes to the real one."""
    real = subprocess.run(["bash", "-c", "command -v python3"], capture_output=True, text=True).stdout.strip()
    answer = f'echo {fury}; exit 0' if fury else 'exit 1'
    script = directory / "python3"
    script.write_text("#!/usr/bin/env bash\n"
                      f'case "$*" in *importlib.metadata*) {answer} ;; esac\n'
                      f'exec {real} "$@"\n')
    script.chmod(script.stat().st_mode | stat.S_IEXEC)


@pytest.mark.fury_free("its verdict cannot depend on the FURY: the kit's bash script, its probes faked")
@pytest.mark.parametrize("fury, backend", [("2.0.0", "pygfx"), ("0.12.0", "vtk"), ("2.1.0", "fury21")])
def test_without_backend_the_kit_follows_the_fury_you_have(tmp_path, fury, backend):
    """Issue 30, point 6: ``./kit run`` meant FURY 0.12 whatever the user had; it follows the FURY of
    the python3 it is called with, and says so with how to choose the other."""
    _fake_python3(tmp_path, fury)
    env = {k: v for k, v in os.environ.items() if k != "KIT_BACKEND"}
    env["PATH"] = f"{tmp_path}{os.pathsep}{os.environ['PATH']}"
    env["KIT_PYTHON"] = subprocess.run(["bash", "-c", "command -v python3"], capture_output=True, text=True).stdout.strip()
    done = subprocess.run([str(KIT), "missing"], env=env, capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    assert f"kit: backend {backend} (your python3 has FURY {fury};" in done.stderr, done.stderr
    given = subprocess.run([str(KIT), "missing", "--backend", "vtk"], env=env, capture_output=True, text=True, timeout=60)
    assert "kit: backend" not in given.stderr, given.stderr  # a backend given is not second-guessed


def test_the_kits_tests_run_with_bytecode_caches(tmp_path):
    """``./kit test`` unsets PYTHONDONTWRITEBYTECODE for the processes it starts: each would otherwise compile
    the kit from source and rewrite its asserts again (2.6 s of CPU a pytest run against 2.0 s, measured;
    docs/numbers.md, "Tiers"). A plugin loaded into the run says what its process was given, and stops it."""
    from conformance import backends

    (tmp_path / "envprobe.py").write_text(
        "import os, pathlib, pytest\n\n"
        "def pytest_configure(config):\n"
        f"    pathlib.Path({str(tmp_path / 'seen')!r}).write_text(repr(os.environ.get('PYTHONDONTWRITEBYTECODE')))\n"
        "    pytest.exit('probed', returncode=0)\n")
    env = {**os.environ, "PYTHONDONTWRITEBYTECODE": "1", "PYTHONPATH": str(tmp_path)}
    done = subprocess.run([str(KIT), "test", "--backend", backends.NAME, "-p", "envprobe", "-q"], env=env,
                          capture_output=True, text=True, timeout=300)
    assert (tmp_path / "seen").exists(), f"the probe did not run: {done.stdout[-500:]}{done.stderr[-500:]}"
    seen = (tmp_path / "seen").read_text()
    assert seen == "None", f"./kit test ran pytest with PYTHONDONTWRITEBYTECODE={seen}, but should unset it"
