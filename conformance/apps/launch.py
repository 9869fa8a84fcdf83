"""Running an app in a process of its own and reading back what it recorded.

The app runs as ``python -m conformance.apps.child`` (:mod:`conformance.apps.child`) with this
interpreter, so its globals, the kit's patches, and whatever the app does to the process (exit, crash,
hang) stay there. ``timeout`` bounds the whole run; an app that exceeds it, crashes or refuses to hand
over its loop gives :class:`AppFailed` with one paragraph saying which.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

from conformance.apps import recording as recording_mod
from conformance.errors import ConformanceError

__all__ = ["AppFailed", "KitFailed", "record"]

#: seconds an app's whole run may take before the kit stops it
DEFAULT_TIMEOUT = 300.0


class AppFailed(ConformanceError):
    """The app could not be run to a recording; the message says why, in one paragraph."""


class KitFailed(ConformanceError):
    """The kit's own code failed while it ran the app: a fault of the kit, not a verdict on the app. The
    message says so, with the kit's traceback, so that it can be reported and is never read as the app's."""


def record(script: str | os.PathLike, *, ticks: int = 120, events=(), tick_function: str | None = None,
           timeout: float = DEFAULT_TIMEOUT) -> recording_mod.Recording:
    """Run the app ``script`` under the kit for up to ``ticks`` ticks, applying ``events`` (dicts as
    :func:`conformance.apps.perturb.as_dict` writes them), and return its recording."""
    script = Path(script)
    if not script.is_file():
        raise AppFailed(f"app={str(script)!r}: no such file; give the path of the Python script that runs your simulation")
    with tempfile.TemporaryDirectory(prefix="conformance-app-") as work:
        out = Path(work) / "recording.npz"
        command = [sys.executable, "-m", "conformance.apps.child", str(script), "--out", str(out),
                   "--ticks", str(int(ticks)), "--events", json.dumps(list(events))]
        if tick_function:
            command += ["--tick", tick_function]
        env = dict(os.environ)
        env.setdefault("PYTHONFAULTHANDLER", "1")
        try:
            done = subprocess.run(command, capture_output=True, text=True, timeout=timeout, env=env,
                                  stdin=subprocess.DEVNULL)
        except subprocess.TimeoutExpired as exc:
            raise AppFailed(f"{script}: the app did not finish {ticks} ticks within {timeout:g} s and was stopped "
                            f"(a callback that never returns, or a loop of its own the kit did not take over). "
                            f"Its last output: {_tail(exc.stderr)}") from None
        fault = Path(str(out) + ".kit-error")
        if fault.exists():
            raise KitFailed(f"{script}: the kit itself failed while it ran the app, a fault of the kit and not of "
                            f"your program (nothing is judged; please report it with what follows): "
                            f"{fault.read_text(encoding='utf-8').strip()}")
        error = Path(str(out) + ".error")
        if error.exists():
            raise AppFailed(error.read_text(encoding="utf-8").strip())
        if done.returncode != 0 or not out.exists():
            how = f"was killed by signal {-done.returncode}" if done.returncode < 0 else f"exited with status {done.returncode}"
            raise AppFailed(f"{script}: the app's process {how} before the kit had its recording (the process crashed). "
                            f"Its last output: {_tail(done.stderr)}")
        return recording_mod.load(out)


def _tail(text, lines: int = 12) -> str:
    if isinstance(text, bytes):
        text = text.decode("utf-8", "replace")
    kept = [line for line in (text or "").strip().splitlines() if "pybullet build time" not in line]
    return "\n".join(kept[-lines:]) or "(nothing)"
