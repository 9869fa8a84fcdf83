"""The per-scene verdict table at the end of a run: a scene is PASS only when every check of it the run
selected ran and passed (issue 30, point 3: after Ctrl-C, or with ``-x``, scenes not fully run printed
PASS, and a person reading a CI log saw PASS).

Read from the printed table, as a person reads it."""

from __future__ import annotations

import os
import re
from pathlib import Path

import pytest

TESTS = str(Path(__file__).resolve().parent)
SCENES = "free_fall or chain or sliding_box"


@pytest.fixture
def table(pytester, monkeypatch):
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join(filter(None, [TESTS, os.environ.get("PYTHONPATH")])))

    def run(*args):
        result = pytester.runpytest_subprocess("--pyargs", "conformance", "-p", "no:cacheprovider", "-k", SCENES, *args)
        text = result.stdout.str()
        rows = dict((m.group(2), (m.group(1), m.group(3))) for m in
                    re.finditer(r"^(PASS|FAIL|SKIP|INCOMPLETE|NOT RUN) +(\w+) +(.*)$", text, re.M))
        return result, rows, text
    return run


@pytest.mark.parametrize("isolation", ["auto", "none"])
@pytest.mark.full("whole kit runs stopped or run to the end to read the per-scene verdict lines: printing, not discrimination")
def test_a_run_stopped_by_x_calls_no_scene_it_did_not_finish_pass(table, isolation):
    result, rows, text = table("--sync", "wrong_syncs:OneStepLate", "-x", "--conformance-isolation", isolation)
    assert result.ret == pytest.ExitCode.TESTS_FAILED, text
    assert set(rows) == {"free_fall", "chain", "sliding_box"}, text
    assert [scene for scene, (verdict, _) in rows.items() if verdict == "FAIL"], text
    assert all(verdict != "PASS" for verdict, _ in rows.values()), text
    assert all(verdict == "FAIL" or "checks not run" in detail for verdict, detail in rows.values()), text


@pytest.mark.full("whole kit runs stopped or run to the end to read the per-scene verdict lines: printing, not discrimination")
def test_an_interrupted_run_calls_no_scene_it_did_not_finish_pass(table):
    """Ctrl-C while a sync runs (the sync raises KeyboardInterrupt at free_fall's 50th call)."""
    result, rows, text = table("--sync", "hanging_syncs:InterruptedOnFreeFall", "--conformance-isolation", "none")
    assert result.ret == pytest.ExitCode.INTERRUPTED, text
    assert rows and all(verdict != "PASS" for verdict, _ in rows.values()), text
    assert any(verdict in ("INCOMPLETE", "NOT RUN") for verdict, _ in rows.values()), text


@pytest.mark.full("whole kit runs stopped or run to the end to read the per-scene verdict lines: printing, not discrimination")
def test_a_whole_run_calls_its_scenes_pass(table):
    result, rows, text = table("--sync", "reference")
    assert result.ret == pytest.ExitCode.OK, text
    assert rows == {scene: ("PASS", rows[scene][1]) for scene in ("free_fall", "chain", "sliding_box")}, text
    assert all("not run" not in detail for _, detail in rows.values()), text


def test_a_pass_of_some_checks_of_a_scene_says_the_others_were_not_selected(table):
    """A -k that selects a few of a scene's checks: PASS is for those, and the line says so."""
    # the last -k is pytest's: it replaces the fixture's, so it names the scenes again
    result, rows, text = table("--sync", "reference", "-k", f"test_vertices_match_poses_every_frame and ({SCENES})")
    assert result.ret == pytest.ExitCode.OK, text
    assert set(rows) == {"free_fall", "chain", "sliding_box"}, text
    assert all(verdict == "PASS" and "1 passed" in detail and "of its checks not selected (-k, -m)" in detail
               for verdict, detail in rows.values()), text
