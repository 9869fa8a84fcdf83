"""A command the kit prints runs as printed from where the user is (issue 30). After ``./kit``, whose
environment is never activated, ``python`` and ``pytest`` on the user's PATH may lack the kit or have
the other FURY: the printed lines name the kit's interpreter (:mod:`conformance.sync.printed`)."""

from __future__ import annotations

import os
import shlex
import subprocess
import sys
from pathlib import Path


from conformance import apps
from conformance.sync import printed
from conformance.sync.printed import reproduce_command
from conformance.rendering.golden import regen_command

import app_sources


def test_installed_where_the_users_python_is_the_lines_say_python(monkeypatch):
    monkeypatch.delenv(printed.KIT_ENV, raising=False)
    assert reproduce_command("free_fall", "reference", 3, {}).startswith("python -m conformance check free_fall")
    assert regen_command("free_fall").startswith("python -m conformance regen free_fall")
    assert printed.pytest() == ["pytest"]


def test_after_kit_the_lines_name_the_kits_interpreter_from_any_directory(monkeypatch, tmp_path):
    monkeypatch.setenv(printed.KIT_ENV, "vtk")
    monkeypatch.chdir(tmp_path)
    for line in (reproduce_command("free_fall", "reference", 3, {}), regen_command("free_fall"),
                 apps.reproduce_command("app.py", 10)):
        interpreter = shlex.split(line)[0]
        assert interpreter != "python" and Path(interpreter).samefile(sys.executable), line
    assert printed.pytest()[1:] == ["-m", "pytest"]


def test_a_printed_reproduce_line_runs_as_printed_where_the_user_is(monkeypatch, tmp_path):
    """The app's reproduce line, printed under ``./kit`` and run by a shell from the user's directory with
    a PATH whose ``python`` is not the kit's."""
    monkeypatch.setenv(printed.KIT_ENV, "vtk")
    monkeypatch.chdir(tmp_path)
    (tmp_path / "app.py").write_text(app_sources.SOURCE, encoding="utf-8")
    line = apps.reproduce_command("app.py", 5) + " --perturbed 0"
    bare = tmp_path / "bin"
    bare.mkdir()
    (bare / "python").write_text("#!/bin/sh\necho 'not the kit' >&2; exit 9\n")
    (bare / "python").chmod(0o755)
    env = {**os.environ, "PATH": f"{bare}{os.pathsep}{os.environ['PATH']}"}
    done = subprocess.run(line, shell=True, capture_output=True, text=True, env=env, timeout=600)
    assert done.returncode == 0 and "verdict: PASS app.py" in done.stdout, done.stdout[-2000:] + done.stderr[-2000:]


def test_a_reproduce_line_keeps_the_tolerance_its_run_was_given(tmp_path):
    """A run with --conformance-atol 1 passes a sync one step late on free_fall; its reproduce line says
    so, and `check` reads the option: without it the same line fails."""
    import dataclasses

    from conformance.judge.tolerances import DEFAULT

    loose = dataclasses.replace(DEFAULT, atol=1.0)
    line = reproduce_command("free_fall", "wrong_syncs:OneStepLate", 5, {}, tolerance=loose)
    assert "--conformance-atol 1.0" in line and "--conformance-size-rtol" not in line, line
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(Path(__file__).parent), os.environ.get("PYTHONPATH", "")])}
    words = shlex.split(line)[1:]
    loose_run = subprocess.run([sys.executable, *words], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600)
    assert loose_run.returncode == 0 and "PASS free_fall" in loose_run.stdout, loose_run.stdout + loose_run.stderr
    kit_tolerance = [w for w in words if w not in ("--conformance-atol", "1.0")]
    strict_run = subprocess.run([sys.executable, *kit_tolerance], cwd=tmp_path, env=env, capture_output=True, text=True,
                                timeout=600)
    assert strict_run.returncode == 1 and "FAIL free_fall" in strict_run.stdout, strict_run.stdout + strict_run.stderr


def test_a_silhouette_failure_reproduces_with_the_check_itself_not_with_check():
    """`check` compares vertices only: a silhouette's reproduce line reruns the silhouette check."""
    from conformance import sync
    from conformance.sync import runner
    from conformance.rendering.silhouettes import silhouette_check

    with runner.running("free_fall", sync.load("reference")) as run:
        record = silhouette_check(run, "reference", check="test_silhouettes_match_pybullet_at_golden_frames[free_fall]")
    words = shlex.split(record.reproduce)
    assert words[:3] == ["pytest", "--pyargs", "conformance"] and "conformance" in words and "check" not in words[:4]
    assert words[words.index("-k") + 1] == "test_silhouettes_match_pybullet_at_golden_frames[free_fall]", words
    assert record.details["replay"].startswith("python -m conformance check free_fall")
