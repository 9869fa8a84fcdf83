"""The image checks' options: bad values are refused with one line naming the option, value and fix."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest


def _pytest(*args, cwd):
    return subprocess.run([sys.executable, "-m", "pytest", "--pyargs", "conformance", "-p", "no:cacheprovider", "-q",
                           "-k", "test_golden_physics and free_fall", *args],
                          cwd=cwd, env=dict(os.environ), capture_output=True, text=True, timeout=300)


@pytest.mark.parametrize("args, message", [
    (["--conformance-image-tolerance", "loose"],
     "--conformance-image-tolerance='loose' (str), but should be one of auto, same-renderer, other-renderer"),
    (["--conformance-golden-dir", "no/such/dir"], "--conformance-golden-dir='no/such/dir' (str), but should be an "
                                                 "existing directory; it does not exist; give the directory of goldens, "
                                                 "or add --regen-golden to make them there"),
    (["--conformance-results", "a_file"], "--conformance-results='a_file' (str), but should be a directory to write in "
                                          "(made if missing); it is a file"),
])
def test_bad_option_is_a_usage_error(tmp_path, args, message):
    (tmp_path / "a_file").write_text("not a directory")
    run = _pytest(*args, cwd=tmp_path)
    assert run.returncode == pytest.ExitCode.USAGE_ERROR, run.stdout[-2000:] + run.stderr[-2000:]
    assert message in run.stderr, run.stderr[-2000:]


def test_ini_setting_is_read_and_shown_in_the_header(tmp_path):
    (tmp_path / "pytest.ini").write_text("[pytest]\nconformance_image_tolerance = other-renderer\n")
    run = _pytest("-v", cwd=tmp_path)
    assert run.returncode == 0, run.stdout[-2000:]
    assert "image tolerance other-renderer" in run.stdout


def test_header_names_the_automatic_choice_and_the_results(tmp_path):
    run = _pytest("-v", cwd=tmp_path)  # -v cancels -q: the header is printed
    assert run.returncode == 0, run.stdout[-2000:]
    assert ("image tolerance auto (the sync against a live reference render: same-renderer; the live reference against "
            "the golden: same-renderer for goldens this machine's renderer made or that it equals, else other-renderer)"
            in run.stdout)
    assert f"results in {tmp_path / 'conformance-results'}" in run.stdout


@pytest.mark.parametrize("chosen", ["same-renderer", "other-renderer"])
def test_forced_tolerance_set_is_used_by_the_golden_render_check(tmp_path, chosen):
    results = tmp_path / "results"
    run = subprocess.run([sys.executable, "-m", "pytest", "--pyargs", "conformance", "-p", "no:cacheprovider", "-q",
                          "-k", "test_golden_render and free_fall", "--conformance-image-tolerance", chosen,
                          "--conformance-results", str(results)],
                         cwd=tmp_path, env=dict(os.environ), capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stdout[-2000:] + run.stderr[-2000:]
    records = [json.loads(line) for path in results.glob("records-*.jsonl") for line in path.read_text().splitlines()]
    assert records and {r["details"]["tolerance_set"] for r in records} == {chosen}
