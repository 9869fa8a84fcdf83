"""A sync that kills the interpreter fails the checks it crashed, and the run completes the others,
serially too: :mod:`conformance.session.isolation` (issue: syncs that hang or crash)."""

from __future__ import annotations

import json
import os
import subprocess
import time
from pathlib import Path

import pytest

from conformance.session import isolation

from crashing_syncs import CALL, SCENE

CHECKS = (f"(test_vertices_match_poses_every_frame or test_sync_keeps_the_mesh or test_golden_render) "
          f"and ({SCENE} or sliding_box)")
SUBSET = ["--pyargs", "conformance", "-p", "no:cacheprovider", "--hypothesis-profile", "default", "-k", CHECKS]


def _ours(cmdline: bytes) -> bool:
    """Whether a process is one of the kit's: Python, or a pytest-xdist worker, which retitles itself
    ("[pytest-xdist running] …") when setproctitle is installed (mutmut brings it)."""
    return b"python" in cmdline or cmdline.startswith(b"[pytest-xdist")


def _xvfb() -> set[int]:
    """Xvfb servers alive whose parent is gone: left behind. A zombie has died already (whoever inherits
    it reaps it); a server whose parent lives is someone else's, e.g. one of the kit's own background runs
    (tests/background.py) started while this test ran."""
    rows = subprocess.run(["ps", "-C", "Xvfb", "-o", "pid=,stat=,ppid="], capture_output=True, text=True).stdout
    orphans = set()
    for pid, stat, parent in (row.split() for row in rows.splitlines() if row.strip()):
        if not stat.startswith("Z") and (parent == "1" or not Path(f"/proc/{parent}/cmdline").exists()
                                         or not _ours(Path(f"/proc/{parent}/cmdline").read_bytes())):
            orphans.add(int(pid))
    return orphans


@pytest.fixture
def run(pytester, monkeypatch):
    """Run the subset in a fresh pytest process with ``sync``; the result, its JSON records and text."""
    tests = str(Path(__file__).resolve().parent)  # where the run's processes find crashing_syncs
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join(filter(None, [tests, os.environ.get("PYTHONPATH")])))

    def running(sync, *args):
        report = pytester.path / "report.json"
        before = _xvfb()
        result = pytester.runpytest_subprocess(*SUBSET, "--sync", sync, "--conformance-report", str(report), *args)
        left = _xvfb() - before
        deadline = time.monotonic() + 10  # a dead worker's Xvfb gets SIGTERM from the kernel, and takes a moment
        while left and time.monotonic() < deadline:
            time.sleep(0.1)
            left = _xvfb() - before
        assert not left, f"Xvfb {sorted(left)} left running after the run, but should have died with its worker"
        records = json.loads(report.read_text())["records"] if report.exists() else []
        return result, records, result.stdout.str()
    return running


def _outcomes(records) -> dict:
    return {row["nodeid"].split("::")[-1]: row["outcome"] for row in records}


@pytest.mark.parametrize("workers", [
    pytest.param([], id="serial"),  # in CI: the isolation every user's sync gets (the kit's own runs skip it)
    pytest.param(["-n", "2"], id="xdist", marks=pytest.mark.full(
        "a second whole run made to crash, under -n: robustness of the isolation, not discrimination")),
])
def test_a_segfault_fails_its_check_with_where_it_was_and_the_run_goes_on(run, workers):
    result, records, text = run("crashing_syncs:SegfaultsOnFreeFall", *workers)
    assert result.ret == pytest.ExitCode.TESTS_FAILED, text
    assert (f"the process crashed (killed by SIGSEGV) while sync implementation 'crashing_syncs:SegfaultsOnFreeFall' "
            f"ran on scene '{SCENE}' at step {CALL - 1}") in text, text
    assert "Fatal Python error: Segmentation fault" in text and "crashing_syncs.py" in text, text
    assert "reproduce (in one process): pytest --pyargs conformance --sync crashing_syncs:SegfaultsOnFreeFall" in text
    outcomes = _outcomes(records)
    # free_fall's golden render stops at its golden frames, before the 50th call: it passes when it runs
    # first (serially it does); under -n 2 it may come after the crash and fail without running, by design
    golden = {"passed", "failed"} if workers else {"passed"}
    assert len(outcomes) == 6 and all(outcome in (golden if "golden" in name else {"failed"}) if SCENE in name
                                      else outcome == "passed" for name, outcome in outcomes.items()), outcomes
    crashed = [row for row in records if "crashed" in row["kinds"]]
    # one crash per scene, or one per worker that was already running one of the scene's checks (-n 2)
    assert 1 <= len(crashed) <= (2 if workers else 1), crashed
    assert all(row["scene"] == SCENE and row["kinds"]["crashed"]["frame"] == CALL - 1 for row in crashed), crashed
    # the scene's other checks do not crash more workers: they fail at once, naming the crash
    if len(crashed) == 1:
        assert "this check would run the scene with it again, so it fails without running" in text, text
    assert f"FAIL  {SCENE}" in text and "PASS  sliding_box" in text, text
    page = text.split("conformance: report (image checks, failing vertex checks): ")[1].split()[0]
    assert Path(page).is_file(), f"{page}, but the run's report.html was not written"
    html = Path(page).read_text(encoding="utf-8")
    assert 'data-kind="crashed"' in html and "the process crashed (killed by SIGSEGV)" in html, \
        "the crash is not a row of report.html"


@pytest.mark.parametrize("sync, how", [("AbortsOnFreeFall", "killed by SIGABRT"),
                                       ("ExitsOnFreeFall", "exit status 3, without a Python error")])
@pytest.mark.full("a whole kit run made to crash, hang or stop: robustness of the isolation, not discrimination")
def test_an_abort_or_an_exit_is_a_verdict_too(run, sync, how):
    result, records, text = run(f"crashing_syncs:{sync}")
    assert result.ret == pytest.ExitCode.TESTS_FAILED, text
    assert f"the process crashed ({how}" in text and f"scene '{SCENE}' at step {CALL - 1}" in text, text
    assert _outcomes(records)["test_vertices_match_poses_every_frame[sliding_box]"] == "passed", text


@pytest.mark.full("a whole kit run made to crash, hang or stop: robustness of the isolation, not discrimination")
def test_a_loop_in_c_that_the_alarm_cannot_stop_is_stopped_by_the_watchdog(run):
    """A call looping inside C never sees the per-call alarm; the controller stops its worker at twice the
    limit and 5 s more (here 1 s: 7 s), and the check fails saying so, where it was, and the run goes on."""
    result, records, text = run("crashing_syncs:LoopsInCOnFreeFall", "--conformance-sync-timeout", "1")
    assert result.ret == pytest.ExitCode.TESTS_FAILED, text
    assert "stopped by the kit after" in text and "looping in C code" in text, text
    assert f"scene '{SCENE}' at step {CALL - 1}" in text and "crashing_syncs.py" in text, text
    assert _outcomes(records)["test_vertices_match_poses_every_frame[sliding_box]"] == "passed", text


@pytest.mark.full("a whole kit run made to crash, hang or stop: robustness of the isolation, not discrimination")
def test_a_right_sync_of_the_users_is_isolated_and_passes(run):
    result, records, text = run("conformance.implementations.reference:ReferenceSync")
    assert result.ret == pytest.ExitCode.OK, text
    assert "1 worker" in text or "bringing up nodes" in text, f"not run in a worker process:\n{text}"
    assert set(_outcomes(records).values()) == {"passed"}


def test_without_isolation_a_crash_ends_the_run_as_it_would_without_the_kit(run):
    result, records, text = run("crashing_syncs:SegfaultsOnFreeFall", "--conformance-isolation", "none")
    assert result.ret not in (pytest.ExitCode.OK, pytest.ExitCode.TESTS_FAILED), text  # killed: no verdict
    assert records == []


@pytest.mark.full("a whole kit run made to crash, hang or stop: robustness of the isolation, not discrimination")
def test_x_stops_at_the_first_failure_with_pytests_own_exit_status(run):
    result, records, text = run("crashing_syncs:SegfaultsOnFreeFall", "-x")
    assert result.ret == pytest.ExitCode.TESTS_FAILED, text  # not xdist's INTERRUPTED
    assert "stopping after 1 failures" in text and "crashing_syncs.py" in text, text


def test_an_isolation_that_is_not_a_choice_is_refused(pytester):
    result = pytester.runpytest(*SUBSET, "--conformance-isolation", "threads")
    assert result.ret == pytest.ExitCode.USAGE_ERROR
    assert "threads" in result.stderr.str() and "auto" in result.stderr.str()


def test_the_crashed_checks_words_select_it_again():
    assert isolation._test_words("test_vertices.py::test_sync_keeps_the_mesh[free_fall]") == \
        "test_sync_keeps_the_mesh and free_fall"
    assert isolation._test_words("test_scenes.py::test_draws_its_collision_geometry[first-chain]") == \
        "test_draws_its_collision_geometry and first and chain"
