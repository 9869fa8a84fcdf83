"""Child processes of the kit's tests, on a renderer of their own.

A test that wants another driver (softpipe, zink, a broken one) runs the kit in a child with the
driver variables set there, never in this process's environment: the kit's background runs
(tests/background.py) start processes from it at any moment of the session.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import conformance
from conformance.backends import display

__all__ = ["environment", "run", "said"]


def environment(**variables) -> dict[str, str]:
    """This process's environment for a child of the kit's, with every driver variable replaced by
    ``variables``, and this checkout's ``conformance`` first on the path (a worktree's, not an install's)."""
    from conformance.backends import renderer_start as rs

    dropped = set(rs.GL_VARIABLES + rs.WGPU_VARIABLES) | {rs.PROBED_VARIABLE, "PYTHONFAULTHANDLER"}
    env = {k: v for k, v in display.child_environment().items() if k not in dropped}
    checkout = str(Path(conformance.__file__).resolve().parents[1])
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [checkout, os.environ.get("PYTHONPATH")]))
    return {**env, **variables}


def run(argv, cwd, *, timeout: float = 300, **variables) -> subprocess.CompletedProcess:
    """``python argv`` in ``cwd`` with ``variables``, its output captured."""
    return subprocess.run([sys.executable, *argv], cwd=cwd, env=environment(**variables), capture_output=True,
                          text=True, timeout=timeout, stdin=subprocess.DEVNULL)


def said(done: subprocess.CompletedProcess) -> str:
    return f"status {done.returncode}\n{done.stdout[-3000:]}\n{done.stderr[-3000:]}"
