"""``pytest -n 2`` (pytest-xdist) gives the same verdicts as a serial run: every check, with the same
outcome, on a sync that passes some checks and fails others. Each worker builds its own pyBullet
clients and starts its own display; the derandomized ``triage`` profile makes both runs try the
same Hypothesis examples, so any difference is the kit's, not chance's."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

import background
from conformance.discrimination import verdicts

TESTS = Path(__file__).resolve().parent
#: Fails on pendulum (two multibodies), passes on the rest.
SPEC = "wrong_syncs:FirstMultibodyOnly"
SUBSET = ["-k", "pendulum or chain or free_fall"]


def _env() -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k not in ("CONFORMANCE_SYNC", "DISPLAY")}
    env["PYTHONPATH"] = os.pathsep.join([str(TESTS), *filter(None, os.environ.get("PYTHONPATH", "").split(os.pathsep))])
    return env


def _verdicts(outcome: verdicts.Outcome) -> dict[str, str]:
    # By file and test, not by the whole node id: the runs start in background threads while other tests
    # chdir (pytester), and pytest's rootdir, hence the ids' "conformance/" prefix, follows the directory
    # a run starts in (seen in CI: the same 30 verdicts, ids with and without the prefix).
    return {r["nodeid"].rsplit("/", 1)[-1]: r["outcome"] for r in outcome.records}


RUNS = {"parallel:serial": lambda: verdicts.check(SPEC, pytest_args=SUBSET, env=_env()),
        "parallel:xdist": lambda: verdicts.check(SPEC, pytest_args=[*SUBSET, "-n", "2"], env=_env())}


def background_runs(items) -> dict:
    """Both runs start with the session (``background``)."""
    return {key: (0.5, call) for key, call in RUNS.items()}


def test_parallel_run_gives_the_serial_verdicts():
    serial, parallel = (background.result(key, call) for key, call in RUNS.items())
    assert serial.exitstatus == parallel.exitstatus == pytest.ExitCode.TESTS_FAILED, (serial.stderr, parallel.stderr)
    assert {"passed", "failed"} <= set(_verdicts(serial).values()), "the run should both pass and fail checks"
    assert _verdicts(parallel) == _verdicts(serial)
