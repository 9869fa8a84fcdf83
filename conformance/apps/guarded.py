"""pyBullet reads of an app's bodies, tried first in a forked copy of the app's process.

pyBullet can crash the process on a read of a body it built itself: ``getCollisionShapeData`` dies of
signal 11 on every MJCF capsule given by ``fromto`` (pybullet 3.2.7: ``mjcf/ant.xml``, ``humanoid.xml``,
``capsule_fromtoX.xml`` and most of pybullet_data's other MJCF models). The app never makes that call; the
kit does, to know each frame's shapes, and a program that runs alone must not die under the kit. The next
model brings the next crash, so nothing here knows which models or calls are bad:

* :func:`run` runs a *plan* (a function of a ``call`` and the clients to read, which makes its risky reads
  through that ``call``) first in a child forked from this process (:func:`os.fork`: the same bodies in the
  same pyBullet state). The child says over a pipe which call it is about to make and that it returned,
  and ends with :func:`os._exit` (nothing of this process's exit runs twice).
* A call the child never returned from is never made in this process: the parent keeps it, forks again for
  the rest (the child refuses the calls already kept), and at last runs the plan here with those calls
  refused: each raises :class:`Refused`, which the plan turns into what it leaves out and says so.
* Only clients connected with ``p.DIRECT`` are tried: a GUI client's calls go to a server thread that a
  forked child does not have, so they would hang there. The child runs the plan on the others alone (and
  stops at a call on any other client); the GUI client's reads are made here as before. So are the rest
  of the reads when a child is silent for :data:`TIMEOUT` s (it is killed), dies outside a call, or cannot
  be forked.
* The child's crash leaves no trace in the app's output: faulthandler is off there (its dump would read as
  the app's own crash, :mod:`conformance.apps.launch`), its stdout and stderr go nowhere (pyBullet's
  warnings would be printed twice), it writes no core file, and the app's signal handlers are not its own.

Cost: one fork per plan when nothing crashes, 8 to 11 ms a run. Measured in the app's own process (run by
:func:`conformance.apps.launch.record`, the kit's patches in place): a script that wraps
:func:`conformance.apps.bodies.frames_of`, then runs ``examples/vtk/kuka.py`` (pybullet_data's
``kuka_iiwa/model.urdf``, 8 frames), timed 15 calls of it with the guard and 15 with the reads made directly
(:func:`_direct` answering no: no fork), twice each way in turn, and kept the lower median: 66 to 70 ms
against 58 ms on FURY 0.12 in three such measurements on a 2-core machine shared with other work
(``examples/pygfx/kuka.py`` on FURY 2: 67 against 58 to 59 ms). A bare fork, one word over the pipe and the
child's exit take 3 ms of it (a process that imported FURY 0.12); the reads themselves 0.3 ms; trimesh's
reading of the visual meshes, which the child does not do, is most of the 58 ms. On ``mjcf/ant.xml``, twelve
of whose links crash pyBullet, the thirteen forks make ``frames_of`` take 52 to 66 ms (it cannot be run
without them). The child's two words a call grow with the bodies: 1,000 boxes on one client took 130 against
92 ms (the same way, 7 calls each, in a process that imported FURY 0.12), once a run.
"""

from __future__ import annotations

import contextlib
import faulthandler
import os
import select
import signal
import warnings
from typing import Callable, Iterable, TypeVar

import pybullet

try:
    import resource
except ImportError:  # not on Windows, which has no fork either
    resource = None

__all__ = ["MOST_FORKS", "TIMEOUT", "Refused", "label", "run"]

T = TypeVar("T")

#: Seconds a child may go without a word before it is taken for hung, killed, and its reads made here.
TIMEOUT = 5.0
#: Children forked for one plan at most: each finds one more call that crashes, and a model with more such
#: calls than this is one whose remaining reads are made here as before.
MOST_FORKS = 256


class Refused(Exception):
    """``call`` (as :func:`label` writes it) ended a forked copy of this process (``how``: "signal 11,
    SIGSEGV", "exit status 1"), so it was not made in this one."""

    def __init__(self, call: str, how: str):
        self.call, self.how = call, how
        super().__init__(f"{call} ended a forked copy of this process ({how}), so it was not made in this one")


class _Untried(BaseException):
    """In the child: a call on a client it may not call (not ``p.DIRECT``). A ``BaseException``, so that no
    handler of the plan's takes it for a pyBullet error and goes on."""


def label(function, args: tuple, kwargs: dict) -> str:
    """``getCollisionShapeData(1, -1, physicsClientId=0)``: the call as written, one line, the same in the
    child and here (its arguments are pyBullet's ids and flags)."""
    words = [repr(a) for a in args] + [f"{k}={v!r}" for k, v in sorted(kwargs.items())]
    return f"{getattr(function, '__name__', repr(function))}({', '.join(words)})".replace("\n", " ")


class _Caller:
    """The ``call`` a plan is handed: refuses the calls known to crash; in a child (``pipe``), says what it
    is about to call and that the call returned, on the clients it may call."""

    def __init__(self, refused: dict[str, str], pipe: int | None = None, clients: frozenset = frozenset()):
        self.refused, self.pipe, self.clients = refused, pipe, clients

    def __call__(self, function, *args, **kwargs):
        call = label(function, args, kwargs)
        if call in self.refused:
            raise Refused(call, self.refused[call])
        if self.pipe is None:
            return function(*args, **kwargs)
        if kwargs.get("physicsClientId", 0) not in self.clients:
            raise _Untried
        _send(self.pipe, f"call {call}")
        try:
            return function(*args, **kwargs)
        finally:
            _send(self.pipe, "done")


def _send(pipe: int, line: str) -> None:
    os.write(pipe, (line + "\n").encode("utf-8"))


def _direct(client: int) -> bool:
    """Whether ``client`` is connected with ``p.DIRECT``: the one connection whose physics runs in the calling
    thread, and so in a forked child too (a GUI's runs in a thread of its own, shared memory and TCP in
    another process, where a copy's read would be made on the real world)."""
    try:
        return pybullet.getConnectionInfo(physicsClientId=client).get("connectionMethod") == pybullet.DIRECT
    except pybullet.error:
        return False


def run(plan: Callable[[Callable, list[int]], T], clients: Iterable[int]) -> T:
    """``plan(call, clients)``, the reads of the bodies on ``clients``, in this process; each read it makes
    through ``call`` (``call(function, *args, **kwargs)``, ``physicsClientId`` among them) tried first in
    forked copies of this process, which run ``plan(call, those of clients connected with p.DIRECT)``. A
    read that crashed a copy raises :class:`Refused` here."""
    clients = list(clients)
    forkable = [c for c in clients if _direct(c)]
    refused: dict[str, str] = {}
    if forkable and hasattr(os, "fork"):
        for _ in range(MOST_FORKS):
            crashed = _trial(plan, refused, forkable)
            if crashed is None:
                break
            refused[crashed[0]] = crashed[1]
    return plan(_Caller(refused), clients)


def _trial(plan, refused: dict[str, str], clients: list[int]) -> tuple[str, str] | None:
    """Run ``plan`` in a forked child: the call it died in and how, or None when there is nothing more to
    learn (it finished, stopped at a client it may not call, went silent, died outside a call, or no
    child could be forked)."""
    read, write = os.pipe()
    try:
        with warnings.catch_warnings():
            # Python 3.12 warns of a fork in a process with threads: the child runs no other thread's code.
            warnings.simplefilter("ignore", DeprecationWarning)
            pid = os.fork()
    except OSError:
        os.close(read)
        os.close(write)
        return None
    if pid == 0:
        os.close(read)
        _child(plan, refused, clients, write)
    os.close(write)
    try:
        pending, silent = _listen(read)
    except BaseException:  # interrupted (Ctrl-C): the child neither outlives this process nor stays a zombie
        _end(pid)
        raise
    finally:
        os.close(read)
    if silent:
        _end(pid)
        return None
    try:
        status = os.waitpid(pid, 0)[1]
    except ChildProcessError:  # an app that ignores SIGCHLD has its children reaped for it
        status = None
    return None if pending is None else (pending, _how(status))


def _end(pid: int) -> None:
    """Kill the child ``pid`` and reap it."""
    with contextlib.suppress(OSError):
        os.kill(pid, signal.SIGKILL)
    with contextlib.suppress(ChildProcessError):
        os.waitpid(pid, 0)


def _listen(pipe: int) -> tuple[str | None, bool]:
    """What the child said until it closed the pipe: the call it began and never returned from (None if
    none), and whether it went silent for :data:`TIMEOUT` s."""
    buffer, pending = b"", None
    while True:
        ready, _, _ = select.select([pipe], [], [], TIMEOUT)
        if not ready:
            return pending, True
        chunk = os.read(pipe, 65536)
        if not chunk:
            return pending, False
        *lines, buffer = (buffer + chunk).split(b"\n")
        for line in lines:
            word, _, rest = line.decode("utf-8", "replace").partition(" ")
            pending = rest if word == "call" else None


def _how(status: int | None) -> str:
    """How the child ended, in words: "signal 11, SIGSEGV", "exit status 1" (pyBullet calls ``exit`` on
    some errors), "unknown status" (reaped by someone else)."""
    if status is None:
        return "unknown status"
    code = os.waitstatus_to_exitcode(status)
    if code < 0:
        with contextlib.suppress(ValueError):
            return f"signal {-code}, {signal.Signals(-code).name}"
        return f"signal {-code}"
    return f"exit status {code}"


def _child(plan, refused: dict[str, str], clients: list[int], pipe: int) -> None:
    """In the forked child: the plan on ``clients``, its calls said on ``pipe``; never returns."""
    try:
        _quiet()
        plan(_Caller(refused, pipe, frozenset(clients)), clients)
    except BaseException:  # noqa: BLE001  whatever the plan raises here it raises in the parent too, where it counts
        pass
    finally:
        with contextlib.suppress(OSError):
            _send(pipe, "end")
        os._exit(0)


def _quiet() -> None:
    """Leave no trace of this child's crash in the app's output, files or processes."""
    faulthandler.disable()
    nowhere = os.open(os.devnull, os.O_WRONLY)
    os.dup2(nowhere, 1)
    os.dup2(nowhere, 2)
    if resource is not None:
        with contextlib.suppress(OSError, ValueError):
            resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
    for number in (signal.SIGINT, signal.SIGTERM):  # the app's handlers, and the kit's that stops its X display
        with contextlib.suppress(OSError, ValueError):
            signal.signal(number, signal.SIG_DFL)
