"""A virtual X display for off-screen rendering when none is set.

VTK 9.3's wheels render through X (GLX) only, so without ``DISPLAY`` the kit starts Xvfb through
PyVirtualDisplay, once per process, and stops it at exit (or when the pytest session ends).
"""

from __future__ import annotations

import atexit
import contextlib
import os
import shutil

from conformance.errors import DisplayUnavailable

__all__ = ["ensure_display", "on_stop", "stop_display", "virtual_display"]

_started = None  # the pyvirtualdisplay.Display this process started, if any
_on_stop = []  # callbacks that let go of X resources before the display goes away

INSTALL_HINT = (
    "install it with `sudo apt-get install xvfb` (Debian/Ubuntu; `dnf install xorg-x11-server-Xvfb` on Fedora), "
    "or set DISPLAY to an X server you already have"
)


def ensure_display() -> str:
    """Return the X display to render on, starting Xvfb if ``DISPLAY`` is unset."""
    global _started
    if os.environ.get("DISPLAY"):
        return os.environ["DISPLAY"]
    if shutil.which("Xvfb") is None:
        raise DisplayUnavailable(
            "Off-screen rendering needs an X server: DISPLAY is not set and the virtual X server "
            f"Xvfb is not on PATH; {INSTALL_HINT}."
        )
    from pyvirtualdisplay import Display

    display = Display(visible=False, size=(1280, 1024), color_depth=24)
    try:
        display.start()
    except Exception as exc:  # pyvirtualdisplay raises several unrelated types
        raise DisplayUnavailable(f"Xvfb is installed but did not start ({type(exc).__name__}: {exc}); {INSTALL_HINT}.") from exc
    _started = display
    atexit.register(stop_display)
    return os.environ["DISPLAY"]


def on_stop(callback) -> None:
    """Call ``callback()`` before the display this process started is stopped (once)."""
    _on_stop.append(callback)


def stop_display() -> None:
    """Stop the Xvfb this process started (restores the previous DISPLAY); no-op otherwise.
    Whatever holds a connection to it is released first, or Xlib kills the process at exit."""
    global _started
    while _on_stop:
        _on_stop.pop()()
    if _started is not None:
        display, _started = _started, None
        display.stop()


@contextlib.contextmanager
def virtual_display():
    """``with virtual_display():`` renders inside, and leaves no Xvfb behind."""
    owned = _started is None and not os.environ.get("DISPLAY")
    ensure_display()
    try:
        yield
    finally:
        if owned:
            stop_display()
