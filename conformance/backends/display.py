"""A virtual X display for off-screen rendering when none is set, and connections to it.

VTK 9.3's wheels render through X (GLX) only, so without ``DISPLAY`` the kit starts its own Xvfb,
once per process, and stops it at exit (or when the pytest session ends). What is guaranteed:

* ``DISPLAY`` set: the kit uses it and never starts or stops a server.
* The Xvfb the kit starts dies with the process that started it, however that process ends: an
  orderly exit stops it (``atexit``, :func:`stop_display`, :func:`virtual_display`); ``SIGTERM``
  (what CI sends a cancelled or timed-out job) stops it through a handler installed while the kit
  owns a display, after which the process dies of ``SIGTERM`` as it would have (status 128+15); and
  any other death (``SIGKILL``, a crash) reaches Xvfb as ``SIGTERM`` through the kernel's
  parent-death signal (Linux ``PR_SET_PDEATHSIG``), which Xvfb takes as an orderly shutdown that
  removes its lock file and socket.
* Xvfb missing: :class:`~conformance.errors.DisplayUnavailable`, with what to install.

Two limits, both of the operating system: the parent-death signal is Linux-only, and it fires when
the *thread* that started Xvfb ends, so it is asked for only when the main thread starts the
server (a server started from another thread is stopped at exit and on ``SIGTERM`` alone); and a
signal handler can only be installed from the main thread, and only over the default disposition
(a process that handles ``SIGTERM`` itself keeps its handler and decides).

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
import select
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
from dataclasses import dataclass

from conformance.errors import DisplayUnavailable

__all__ = [
    "SCREEN",
    "child_environment",
    "close_x_connection",
    "die_with",
    "dies_with_this_process",
    "ensure_display",
    "on_stop",
    "server_pid",
    "stop_display",
    "virtual_display",
    "x_connection",
]

#: The virtual screen: big enough for every picture the kit takes, 24-bit colour as the goldens were made.
SCREEN = "1280x1024x24"
#: How long Xvfb may take to say it is ready, and to stop when asked.
START_TIMEOUT = 30.0
STOP_TIMEOUT = 5.0

#: Attempts, and the first pause between them (doubled each time), when opening an X connection.
CONNECT_ATTEMPTS = 8
CONNECT_PAUSE = 0.05

INSTALL_HINT = (
    "install it with `sudo apt-get install xvfb` (Debian/Ubuntu; `dnf install xorg-x11-server-Xvfb` on Fedora), "
    "or set DISPLAY to an X server you already have"
)

_PR_SET_PDEATHSIG = 1  # from <linux/prctl.h>


@dataclass
class _Server:
    """An Xvfb this process started: the process, the ``DISPLAY`` it serves, the one it replaced."""

    process: subprocess.Popen
    name: str
    previous: str | None
    owner: int  # the pid that started it: a forked child inherits this object but does not own the server
    handler_installed: bool = False


_started: _Server | None = None
_on_stop = []  # callbacks that let go of X resources before the display goes away
_atexit_registered = False


def ensure_display() -> str:
    """Return the X display to render on, starting Xvfb if ``DISPLAY`` is unset."""
    global _started, _atexit_registered
    if os.environ.get("DISPLAY"):
        return os.environ["DISPLAY"]
    if _started is not None and _started.owner == os.getpid() and _started.process.poll() is None:
        # DISPLAY was unset behind the kit's back: go on using the server it runs, not a second one
        os.environ["DISPLAY"] = _started.name
        return _started.name
    executable = shutil.which("Xvfb")
    if executable is None:
        raise DisplayUnavailable(
            "Off-screen rendering needs an X server: DISPLAY is not set and the virtual X server "
            f"Xvfb is not on PATH; {INSTALL_HINT}."
        )
    previous = os.environ.get("DISPLAY")  # set but empty counts as unset, and is put back as it was
    process, name = _start_xvfb(executable)
    _started = _Server(process=process, name=name, previous=previous, owner=os.getpid())
    os.environ["DISPLAY"] = name
    _started.handler_installed = _install_sigterm_handler()
    if not _atexit_registered:
        atexit.register(stop_display)
        _atexit_registered = True
    return name


def server_pid() -> int | None:
    """The pid of the Xvfb this process started and still runs, else ``None`` (for tests and logs)."""
    return _started.process.pid if _started is not None and _started.owner == os.getpid() else None


def child_environment(environ=None) -> dict[str, str]:
    """An environment for a child process of the kit's (a pytest run): this one without ``DISPLAY``
    when that is the Xvfb this process started, which may stop before the child is done (a test that
    restarts the display, this process ending); the child then starts its own."""
    env = dict(os.environ if environ is None else environ)
    if server_pid() is not None and env.get("DISPLAY") == _started.name:
        env.pop("DISPLAY")
    return env


def on_stop(callback) -> None:
    """Call ``callback()`` before the display this process started is stopped (once)."""
    _on_stop.append(callback)


def stop_display() -> None:
    """Stop the Xvfb this process started (restores the previous DISPLAY); no-op otherwise.
    Whatever holds a connection to it is released first, or Xlib kills the process at exit."""
    global _started
    while _on_stop:
        _on_stop.pop()()
    if _started is None:
        return
    server, _started = _started, None
    if server.owner != os.getpid():  # a forked child: the server is its parent's to stop
        return
    if server.handler_installed:
        _restore_sigterm_handler()
    _terminate(server.process)
    if os.environ.get("DISPLAY") == server.name:
        if server.previous is None:
            os.environ.pop("DISPLAY", None)
        else:
            os.environ["DISPLAY"] = server.previous


# -- starting and stopping Xvfb ---------------------------------------------------------------------

def _start_xvfb(executable: str) -> tuple[subprocess.Popen, str]:
    """Start Xvfb on a display number it picks itself (``-displayfd``: no race with other servers
    for a number) and return it once it accepts connections, which is when it writes the number."""
    read_end, write_end = os.pipe()
    # Xvfb writes warnings for its whole life: a file, not a pipe nobody drains, so it never blocks.
    log = tempfile.TemporaryFile()
    command = [executable, "-displayfd", str(write_end), "-screen", "0", SCREEN, "-nolisten", "tcp"]
    try:
        try:
            process = subprocess.Popen(command, stdin=subprocess.DEVNULL, stdout=log, stderr=log,
                                       pass_fds=(write_end,), preexec_fn=dies_with_this_process(),
                                       # its own session: a Ctrl-C or hang-up of the terminal goes to the
                                       # kit, which stops the server once it is done with it
                                       start_new_session=True)
        except OSError as exc:
            raise DisplayUnavailable(f"Xvfb is on PATH ({executable}) but could not be run ({exc.strerror}); "
                                     f"{INSTALL_HINT}.") from None
        os.close(write_end)
        write_end = -1
        number = _read_display_number(read_end)
    finally:
        os.close(read_end)
        if write_end >= 0:
            os.close(write_end)
    if number is None:
        _terminate(process)
        log.seek(0)
        said = _what_went_wrong(log.read().decode("utf-8", "replace"))
        log.close()
        raise DisplayUnavailable(
            f"Xvfb is installed but did not start (exit status {process.returncode}; it said: {said or 'nothing'}): "
            "what it said is what to mend, or set DISPLAY to an X server you already have and the kit uses that."
        )
    log.close()  # Xvfb keeps its own descriptor; the file disappears when it exits
    return process, f":{number}"


def _what_went_wrong(output: str) -> str:
    """Xvfb's error lines (it marks them ``(EE)``), else its last lines: not its usage text."""
    lines = [line.strip() for line in output.splitlines() if line.strip()]
    errors = [line.removeprefix("(EE)").strip() for line in lines if line.startswith("(EE)")]
    return " ".join(line for line in errors if line)[-600:] if any(errors) else " ".join(lines[-3:])[-600:]


def _read_display_number(fd: int) -> int | None:
    """The number Xvfb writes to ``-displayfd`` when it is ready; ``None`` if it exits or takes too long."""
    data, deadline = b"", time.monotonic() + START_TIMEOUT
    while not data.endswith(b"\n"):
        remaining = deadline - time.monotonic()
        if remaining <= 0 or not select.select([fd], [], [], remaining)[0]:
            return None
        chunk = os.read(fd, 32)
        if not chunk:  # Xvfb exited (it holds the only other write end)
            return None
        data += chunk
    try:
        return int(data.strip())
    except ValueError:
        return None


def _terminate(process: subprocess.Popen) -> None:
    """``SIGTERM`` (Xvfb then removes its lock file and socket), ``SIGKILL`` if it lingers; reaped."""
    if process.poll() is None:
        process.terminate()
        try:
            process.wait(STOP_TIMEOUT)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()


@functools.cache
def _prctl():
    """libc's ``prctl`` on Linux, else ``None``."""
    if not sys.platform.startswith("linux"):
        return None
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        return libc.prctl
    except (OSError, AttributeError):
        return None


def dies_with_this_process(*, waited_for: bool = False):
    """A ``preexec_fn`` for ``subprocess.Popen`` that makes the kernel send the child ``SIGTERM`` when
    this process dies, however it dies; ``None`` where that cannot be had (not Linux; not the main
    thread, whose end would fire it early, unless ``waited_for``: the calling thread waits for the
    child, as ``subprocess.run`` does, so it cannot end first). The kit's Xvfb, the pytest run of
    ``python -m conformance run`` and the runs of ``verdicts``/``kill-rate`` are started with it."""
    prctl = _prctl()  # looked up here, in the parent: the child between fork and exec only calls it
    if prctl is None or (threading.current_thread() is not threading.main_thread() and not waited_for):
        return None
    parent = os.getpid()

    def set_death_signal() -> None:
        prctl(_PR_SET_PDEATHSIG, signal.SIGTERM, 0, 0, 0)
        if os.getppid() != parent:  # the parent died before prctl: the signal will never come
            os._exit(1)

    return set_death_signal


def die_with(pid: int) -> None:
    """In a process forked for ``pid`` by a fork server: send this process ``SIGTERM`` when ``pid`` ends,
    however it ends. The parent-death signal cannot say it: the parent is the fork server, which lives on
    while any process it forked does (each holds its "alive" pipe), so a run forked for a kit that was
    killed ran to its end, with its Xvfb (seen: ``precision`` stopped with ``SIGTERM``, its pytest run still
    going a minute later). A daemon thread waits on a pidfd of ``pid`` (Linux 5.3+), else polls it once a
    second; ``SIGTERM`` then takes the process's own way out (its Xvfb stopped by :func:`_on_sigterm`)."""
    try:
        handle = os.pidfd_open(pid)
    except ProcessLookupError:  # gone before this process began
        os.kill(os.getpid(), signal.SIGTERM)
        return
    except (AttributeError, OSError):
        handle = None

    def wait() -> None:
        if handle is not None:
            select.select([handle], [], [])  # readable once pid has ended
        else:
            while _alive(pid):
                time.sleep(1.0)
        os.kill(os.getpid(), signal.SIGTERM)

    threading.Thread(target=wait, name=f"kit-dies-with-{pid}", daemon=True).start()


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's process: it is there
        pass
    return True


# -- SIGTERM -------------------------------------------------------------------------------------

def _on_sigterm(signum, frame) -> None:
    """Stop the display, then die of ``SIGTERM`` as the default disposition would have. No callbacks
    and no unwinding: the process is going away, and code run after the server is gone would only
    make Xlib abort on a dead connection."""
    server = _started
    if server is not None and server.owner == os.getpid():
        _terminate(server.process)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    os.kill(os.getpid(), signal.SIGTERM)


def _install_sigterm_handler() -> bool:
    """Install :func:`_on_sigterm` if this is the main thread and ``SIGTERM`` has its default
    disposition; say whether it was installed."""
    if threading.current_thread() is not threading.main_thread():
        return False
    try:
        if signal.getsignal(signal.SIGTERM) is not signal.SIG_DFL:
            return False
        signal.signal(signal.SIGTERM, _on_sigterm)
    except (ValueError, OSError):  # e.g. an interpreter that is not the main one
        return False
    return True


def _restore_sigterm_handler() -> None:
    try:
        if signal.getsignal(signal.SIGTERM) is _on_sigterm:
            signal.signal(signal.SIGTERM, signal.SIG_DFL)
    except ValueError:  # not the main thread: the handler stays, and does nothing without a server
        pass


# -- X connections -------------------------------------------------------------------------------

@functools.cache  # loaded once: opening and closing a connection both need it
def _xlib():
    path = ctypes.util.find_library("X11")
    if path is None:
        raise DisplayUnavailable("Off-screen rendering needs the X client library libX11, which was not found (the kit "
                                 "loads it to talk to any X server, Xvfb or yours); install it with `sudo apt-get "
                                 "install libx11-6` (Debian/Ubuntu; `dnf install libX11` on Fedora).")
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
