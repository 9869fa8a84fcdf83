"""Whether the renderer can start here, asked before the kit first renders in a process.

VTK 9.3 calls ``abort()`` when it cannot make an OpenGL context ("Cannot create GLX context.
Aborting."), which ends the process that asked (a pytest session, a command) with exit status 134 and
no word from the kit; ``GALLIUM_DRIVER=zink`` without ``LIBGL_ALWAYS_SOFTWARE=1`` does that, as do
``MESA_LOADER_DRIVER_OVERRIDE=zink`` and ``LIBGL_ALWAYS_INDIRECT=1`` under Xvfb. Other settings
crash it (``MESA_GL_VERSION_OVERRIDE=2.1``: a segfault) or leave it drawing nothing
(``MESA_GL_VERSION_OVERRIDE=3.0``: no OpenGL 3.2, an error line, no abort). So before the kit makes
its render window, a short-lived child process makes an 8×8 off-screen window on the same display in
the same environment and draws once (:func:`check_gl`); the child dies instead of the kit.

What is guaranteed:

* :func:`check_gl` raises :class:`~conformance.errors.DisplayUnavailable` (one paragraph: the display
  and the driver variables set, what the child said, what to try) when the child is killed by a
  signal, exits non-zero, finds no OpenGL 3.2 or later, or does not finish within
  :data:`PROBE_TIMEOUT` seconds; otherwise it returns.
* At most one probe per process and environment (``DISPLAY`` and :data:`GL_VARIABLES`): the answer,
  pass or error, is kept for the process. A pass is also left in ``$CONFORMANCE_GL_PROBED``, so a
  child of the kit's with the same display and variables (an app's process) does not probe again.

Cost, once per process: 202–229 ms (median 209 ms, 8 runs, load average 3.5 on this project's 2 cores,
Mesa llvmpipe under Xvfb; up to 360 ms at load 4.6), about half of it importing VTK in the child and
half making the context; a repeated call for the same environment 0.08 ms. Measured with
``python -c "import time; from conformance.backends import display, renderer_start as r; display.ensure_display();
t = time.perf_counter(); r.check_gl(); print(time.perf_counter() - t)"`` (docs/numbers.md). A
whole check takes seconds.

FURY 2 needs no child: wgpu reports a missing adapter or driver as a Python exception (tried:
``WGPU_BACKEND_TYPE=Metal``, ``VK_ICD_FILENAMES`` naming no file, a malformed file or a library
that is no Vulkan driver, ``WGPU_LIB_PATH`` naming no file; ``GALLIUM_DRIVER=zink``,
``WGPU_ADAPTER_NAME`` and ``MESA_VK_DEVICE_SELECT`` with unknown values do not stop it), which
:mod:`conformance.backends.pygfx` words with :func:`asked_for` the same way.
"""

from __future__ import annotations

import hashlib
import os
import re
import signal
import subprocess
import sys

from conformance.errors import DisplayUnavailable

__all__ = ["GL_VARIABLES", "PROBE_TIMEOUT", "WGPU_VARIABLES", "asked_for", "check_gl", "last_words", "set_among"]

#: The environment variables that choose or configure the OpenGL driver VTK gets from Mesa/libglvnd.
GL_VARIABLES = ("GALLIUM_DRIVER", "LIBGL_ALWAYS_SOFTWARE", "MESA_LOADER_DRIVER_OVERRIDE", "LIBGL_ALWAYS_INDIRECT",
                "MESA_GL_VERSION_OVERRIDE", "LIBGL_DRIVERS_PATH", "__GLX_VENDOR_LIBRARY_NAME", "XDG_RUNTIME_DIR")
#: The ones that choose wgpu's adapter and Vulkan driver (FURY 2).
WGPU_VARIABLES = ("WGPU_BACKEND_TYPE", "WGPU_ADAPTER_NAME", "WGPU_POWER_PREFERENCE", "WGPU_LIB_PATH",
                  "VK_ICD_FILENAMES", "VK_DRIVER_FILES", "MESA_VK_DEVICE_SELECT")
#: Seconds the child may take: it needs a fraction of one, but a loaded CI machine is slow to start Python.
PROBE_TIMEOUT = 60.0
#: Where a pass is left for child processes: a digest of the display and the variables it held for.
PROBED_VARIABLE = "CONFORMANCE_GL_PROBED"

# The child opens its own X connection with retries, as the kit does (conformance.backends.display.x_connection),
# so that a server slow to accept a connection is not taken for a driver that cannot start.
_GL_PROGRAM = r"""
import ctypes, ctypes.util, os, sys, time
import vtkmodules.vtkRenderingOpenGL2
from vtkmodules.vtkRenderingCore import vtkRenderer, vtkRenderWindow
xlib = ctypes.CDLL(ctypes.util.find_library("X11"))
xlib.XOpenDisplay.restype, xlib.XOpenDisplay.argtypes = ctypes.c_void_p, [ctypes.c_char_p]
for pause in (0.05, 0.1, 0.2, 0.4, 0.8, 1.6, None):
    connection = xlib.XOpenDisplay(os.environ["DISPLAY"].encode())
    if connection or pause is None:
        break
    time.sleep(pause)
if not connection:
    sys.exit("could not connect to the X display " + os.environ["DISPLAY"])
window = vtkRenderWindow()
window.SetDisplayId("_%016x_p_void" % connection)
window.SetOffScreenRendering(1)
window.SetSize(8, 8)
window.AddRenderer(vtkRenderer())
window.Render()
if not window.SupportsOpenGL():
    sys.exit("VTK found no OpenGL 3.2 or later")
window.Finalize()
"""

_answers: dict[str, str | None] = {}  # environment digest -> None (passed) or the paragraph


def _digest(environ) -> str:
    values = [environ.get(name) for name in ("DISPLAY",) + GL_VARIABLES]
    return hashlib.sha1(repr(values).encode()).hexdigest()[:16]


def check_gl() -> None:
    """Return if VTK can make an OpenGL context on ``$DISPLAY`` (which must be set: call
    :func:`conformance.backends.display.ensure_display` first) in this environment; else raise
    :class:`DisplayUnavailable`. Probes at most once per process and environment."""
    key = _digest(os.environ)
    if key not in _answers and os.environ.get(PROBED_VARIABLE) == key:
        _answers[key] = None  # the parent passed it with this display and these variables
    if key not in _answers:
        _answers[key] = _probe()
        if _answers[key] is None:
            os.environ[PROBED_VARIABLE] = key
    if _answers[key] is not None:
        raise DisplayUnavailable(_answers[key])


def _probe() -> str | None:
    """Run the child; ``None`` if it drew, else the paragraph saying what failed and what to try."""
    from conformance.backends.display import dies_with_this_process

    env = dict(os.environ)
    env.pop("PYTHONFAULTHANDLER", None)  # its stack dump would bury what the driver said
    try:
        # cwd "/": a vtk.py in the working directory must not stand in for VTK
        done = subprocess.run([sys.executable, "-c", _GL_PROGRAM], cwd=os.path.abspath(os.sep), env=env,
                              stdin=subprocess.DEVNULL, capture_output=True, text=True, errors="replace",
                              timeout=PROBE_TIMEOUT, preexec_fn=dies_with_this_process(waited_for=True))
    except subprocess.TimeoutExpired as exc:
        return _paragraph(f"did not finish within {PROBE_TIMEOUT:g} s", exc.stderr)
    if done.returncode == 0:
        return None
    if done.returncode < 0:
        how = f"was killed by signal {-done.returncode} ({_signal_name(-done.returncode)})"
    else:
        how = f"exited with status {done.returncode}"
    return _paragraph(how, done.stderr)


def _signal_name(number: int) -> str:
    try:
        return signal.Signals(number).name
    except ValueError:
        return "unknown signal"


def _paragraph(how: str, stderr) -> str:
    display = os.environ.get("DISPLAY", "")
    drivers = [name for name in set_among(GL_VARIABLES) if name != "XDG_RUNTIME_DIR"]
    if drivers:
        advice = (f"unset {' and '.join(drivers)} to use Mesa's default driver (llvmpipe, no GPU needed); for zink "
                  "set LIBGL_ALWAYS_SOFTWARE=1 GALLIUM_DRIVER=zink and XDG_RUNTIME_DIR to a directory you own, for "
                  "softpipe LIBGL_ALWAYS_SOFTWARE=1 GALLIUM_DRIVER=softpipe")
    else:
        advice = ("check that the X server offers GLX (`glxinfo -B` on that display) and that Mesa's OpenGL driver "
                  "is installed (`sudo apt-get install libgl1-mesa-dri libglx-mesa0` on Debian/Ubuntu), or unset "
                  "DISPLAY to let the kit start its own Xvfb")
    return (f"VTK cannot start its OpenGL renderer on the X display {display!r} with {asked_for(GL_VARIABLES)}: "
            f"an 8x8 test window in a child process {how}, saying: {last_words(stderr)} (in the kit's own process "
            f"this would have aborted the run). To fix it, {advice}.")


def set_among(names) -> list[str]:
    """The variables of ``names`` set to something in this process's environment (empty counts as unset)."""
    return [name for name in names if os.environ.get(name)]


def asked_for(names) -> str:
    """The variables of ``names`` that are set, as ``A='x', B='y'``, else ``none of A, B, … set``."""
    given = [f"{name}={os.environ[name]!r}" for name in set_among(names)]
    return ", ".join(given) if given else f"none of {', '.join(names)} set"


_ANSI = re.compile(r"\x1b\[[0-9;]*m")
_VTK_PREFIX = re.compile(r"^.*?\b(?:ERR|WARN)\|\s*(?:\w+ \(0x[0-9a-f]+\): )?")


def last_words(text, lines: int = 3) -> str:
    """The last ``lines`` distinct lines a process wrote, on one line: colour codes, VTK's log prefix
    (time, thread, file) and pybullet's banner gone; ``(nothing)`` if it wrote nothing else."""
    if isinstance(text, bytes):
        text = text.decode("utf-8", "replace")
    kept: list[str] = []
    for line in (text or "").splitlines():
        line = " ".join(_VTK_PREFIX.sub("", _ANSI.sub("", line)).split())
        if line and "pybullet build time" not in line and line not in kept:
            kept.append(line)
    return "; ".join(kept[-lines:])[-600:] or "(nothing)"
