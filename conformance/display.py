"""A virtual X display for off-screen rendering when none is set, and connections to it.

VTK 9.3's wheels render through X (GLX) only, so without ``DISPLAY`` the kit starts Xvfb through
PyVirtualDisplay, once per process, and stops it at exit (or when the pytest session ends).

VTK opens its own X connection with ``XOpenDisplay`` and calls ``abort()`` when that fails ("bad X
server connection"). While several processes started rendering at once, that happened to about 1 run
in 50 during the kit's development (a stress test of 200 simultaneous connections did not reproduce
it later), so the kit opens the connection itself, retrying, and hands it to VTK (:func:`x_connection`).
"""

from __future__ import annotations

import atexit
import contextlib
import ctypes
import ctypes.util
import functools
import os
import shutil
import time

from conformance.errors import DisplayUnavailable

__all__ = ["close_x_connection", "ensure_display", "on_stop", "stop_display", "virtual_display", "x_connection"]

_started = None  # the pyvirtualdisplay.Display this process started, if any
_on_stop = []  # callbacks that let go of X resources before the display goes away

#: Attempts, and the first pause between them (doubled each time), when opening an X connection.
CONNECT_ATTEMPTS = 8
CONNECT_PAUSE = 0.05

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


@functools.cache  # loaded once: opening and closing a connection both need it
def _xlib():
    path = ctypes.util.find_library("X11")
    if path is None:
        raise DisplayUnavailable(f"Off-screen rendering needs the X client library libX11, which was not found; {INSTALL_HINT}.")
    lib = ctypes.CDLL(path)
    lib.XOpenDisplay.restype = ctypes.c_void_p
    lib.XOpenDisplay.argtypes = [ctypes.c_char_p]
    lib.XCloseDisplay.argtypes = [ctypes.c_void_p]
    return lib


def x_connection() -> int:
    """Open a connection to the X display (started if need be), retrying with back-off while the
    server refuses it; return the ``Display*`` as an integer. Close it with :func:`close_x_connection`."""
    name = ensure_display()
    lib, pause = _xlib(), CONNECT_PAUSE
    for attempt in range(1, CONNECT_ATTEMPTS + 1):
        pointer = lib.XOpenDisplay(name.encode())
        if pointer:
            return pointer
        if attempt < CONNECT_ATTEMPTS:
            time.sleep(pause)
            pause *= 2
    raise DisplayUnavailable(
        f"Could not connect to the X display {name!r} ({CONNECT_ATTEMPTS} attempts over "
        f"{CONNECT_PAUSE * (2 ** (CONNECT_ATTEMPTS - 1) - 1):.0f} s): the X server is not running or refuses "
        f"connections; unset DISPLAY to let the kit start its own Xvfb, or {INSTALL_HINT}."
    )


def close_x_connection(pointer: int) -> None:
    """Close a connection opened by :func:`x_connection`."""
    _xlib().XCloseDisplay(pointer)


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
