"""How the kit writes a command it prints for the user to run (reproduce, regen and replay lines), so that
it runs as printed from where the user is.

Run through ``./kit`` (which sets ``CONFORMANCE_KIT_BACKEND``), the kit lives in a virtual environment of
its own that is never activated: the ``python`` or ``pytest`` on the user's PATH may not have the kit, or
may have the other FURY. There a printed command names that environment's interpreter, by the shorter of
its path relative to the current directory and its absolute path (``.venv/bin/python -m conformance check
…``). Installed where the user's own ``python`` is, the kit prints ``python -m conformance …`` and
``pytest --pyargs conformance …``.
"""

from __future__ import annotations

import json
import os
import shlex
import sys
from typing import Any, Mapping, Sequence

__all__ = ["KIT_ENV", "pytest", "python", "reproduce_command", "rerun_check", "tolerance_arguments"]

#: set by ``./kit`` for every command it runs: the backend it chose
KIT_ENV = "CONFORMANCE_KIT_BACKEND"


def python() -> str:
    """The interpreter word of a printed command."""
    if not os.environ.get(KIT_ENV):
        return "python"
    absolute = os.path.abspath(sys.executable)  # the venv's own link, not the interpreter it points to
    try:
        relative = os.path.relpath(absolute)
    except ValueError:  # another drive (Windows)
        return absolute
    relative = relative if os.sep in relative else os.path.join(".", relative)
    return min(relative, absolute, key=len)


def pytest() -> list[str]:
    """The words that start a printed pytest command."""
    return ["pytest"] if python() == "python" else [python(), "-m", "pytest"]


def tolerance_arguments(tolerance) -> list[str]:
    """The ``--conformance-…`` options that give ``tolerance`` where it is not the kit's default."""
    from conformance.judge.tolerances import DEFAULT

    fields = ("size_rtol", "position_rtol", "atol", "normal_angle")
    return [w for name in fields if tolerance is not None and getattr(tolerance, name) != getattr(DEFAULT, name)
            for w in (f"--conformance-{name.replace('_', '-')}", repr(getattr(tolerance, name)))]


def rerun_check(check_id: str, scene: str, sync: str, tolerance=None, given: Sequence[str] = ()) -> str:
    """The pytest command that runs the check ``check_id`` (its whole id: ``test_x[scene]``) again, with the
    scene's source for a user's scene, the tolerance of this run, and the options ``given``."""
    from conformance.sync import own_scenes

    return shlex.join([*pytest(), "--pyargs", "conformance", "-k", check_id, "--sync", sync,
                       *own_scenes.scene_arguments(scene), *tolerance_arguments(tolerance), *given])


def reproduce_command(scene: str, sync: str, frames: int, params: Mapping[str, Any], events: Sequence = (),
                      tolerance=None) -> str:
    """The command line that replays a run frame by frame and prints every target's error (the vertex
    checks': vertices, normals and announcements), to ``tolerance`` when it is not the kit's."""
    from conformance.sync import own_scenes

    words = [python(), "-m", "conformance", "check", scene, *own_scenes.scene_arguments(scene), "--sync", sync,
             "--frames", str(frames), *tolerance_arguments(tolerance)]
    if params:
        words += ["--params", json.dumps(dict(params), sort_keys=True)]
    if events:
        from conformance.bullet import events as events_module

        words += ["--events", events_module.dumps(events)]
    return shlex.join(words)
