"""A sync call that does not return within the time limit fails its check with where it was, and the
run goes on: :mod:`conformance.sync.time_limit` and ``--conformance-sync-timeout`` (issue: syncs that hang)."""

from __future__ import annotations

import json
import os
import signal
import time
from pathlib import Path

import pytest

from conformance.sync import time_limit

from hanging_syncs import CALL, SCENE

SUBSET = ["--pyargs", "conformance", "-p", "no:cacheprovider", "--sync", "hanging_syncs:HangsOnFreeFall",
          "-k", f"test_vertices_match_poses_every_frame and ({SCENE} or sliding_box)"]


def test_a_call_past_its_limit_is_stopped_even_through_except_exception():
    def swallowing():
        try:
            time.sleep(60)
        except Exception:
            pass

    with pytest.raises(time_limit.Expired) as caught:
        with time_limit.limited(0.2):
            swallowing()
    assert "time.sleep(60)" in time_limit.stack(caught.value)


def test_no_limit_and_a_call_within_it_run_untouched():
    for seconds in (None, 0, 5.0):
        with time_limit.limited(seconds):
            value = sum(range(1000))
        assert value == 499500


def test_someone_elses_alarm_is_put_back():
    previous = signal.signal(signal.SIGALRM, lambda *_: None)
    try:
        signal.setitimer(signal.ITIMER_REAL, 100.0)
        with time_limit.limited(5.0):
            pass
        remaining, _ = signal.getitimer(signal.ITIMER_REAL)
        assert 90.0 < remaining <= 100.0, f"remaining={remaining}, but should be the other alarm's, put back"
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


def _verdicts(report) -> dict:
    """scene → outcome, from the JSON report the run wrote."""
    return {row["scene"]: row["outcome"] for row in json.loads(report.read_text())["records"]}


@pytest.mark.parametrize("workers", [[], ["-n", "2"]], ids=["serial", "xdist"])
def test_a_hanging_sync_fails_its_check_with_where_it_was_and_the_run_goes_on(pytester, monkeypatch, workers):
    tests = str(Path(__file__).resolve().parent)  # where the run's processes find hanging_syncs
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join(filter(None, [tests, os.environ.get("PYTHONPATH")])))
    report = pytester.path / "report.json"
    result = pytester.runpytest_subprocess(*SUBSET, *workers, "--conformance-sync-timeout", "0.5",
                                           "--conformance-report", str(report), "--hypothesis-profile", "default")
    text = result.stdout.str()
    assert result.ret == pytest.ExitCode.TESTS_FAILED, text
    assert f"did not return within 0.5 s on scene '{SCENE}' at step {CALL - 1}" in text, text
    assert "time.sleep(3600)" in text and "hanging_syncs.py" in text, text
    result.assert_outcomes(failed=1, passed=1)
    assert _verdicts(report) == {SCENE: "failed", "sliding_box": "passed"}


def test_a_time_limit_that_is_not_a_number_is_refused(pytester):
    result = pytester.runpytest(*SUBSET, "--conformance-sync-timeout", "soon")
    assert result.ret == pytest.ExitCode.USAGE_ERROR
    assert "--conformance-sync-timeout='soon'" in result.stderr.str() or "soon" in result.stderr.str()
