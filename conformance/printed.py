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

import os
import sys

__all__ = ["KIT_ENV", "pytest", "python"]

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
