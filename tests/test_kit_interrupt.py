"""Ctrl-C on ``./kit run`` (``python -m conformance run``) ends with pytest's summary and the per-scene
table, not a traceback through the kit's own modules (issue 30, point 7)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from conformance.backends.display import child_environment

TESTS = Path(__file__).resolve().parent


def _hear_ctrl_c():
    """A shell runs a command it puts in the background (CI's ``nohup … &``) with SIGINT ignored, the
    ignore is inherited, and Python then never installs its KeyboardInterrupt handler: the sync's Ctrl-C
    fell on deaf ears in CI and 20 checks passed. A terminal's foreground command hears it."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


@pytest.mark.full("a whole run interrupted by Ctrl-C: robustness of the summary, not discrimination")
def test_ctrl_c_on_run_ends_with_the_summary_and_no_traceback(tmp_path):
    environment = {**child_environment(), "PYTHONPATH": os.pathsep.join([str(TESTS), os.environ.get("PYTHONPATH", "")])}
    # A session of its own: the sync's Ctrl-C goes to this run's process group, as a terminal's does.
    run = subprocess.run([sys.executable, "-m", "conformance", "run", "--sync", "hanging_syncs:CtrlCOnFreeFall",
                          "-k", "free_fall"], cwd=tmp_path, capture_output=True, text=True, env=environment,
                         start_new_session=True, preexec_fn=_hear_ctrl_c, timeout=600)
    assert run.returncode == 2, run.stdout[-3000:] + run.stderr[-3000:]  # pytest's "interrupted"
    assert "Traceback" not in run.stderr and "cannot send" not in run.stderr + run.stdout, run.stderr[-3000:]
    assert "conformance verdict per scene" in run.stdout, run.stdout[-3000:]
    assert "INCOMPLETE  free_fall" in run.stdout and "PASS  free_fall" not in run.stdout, run.stdout[-3000:]
