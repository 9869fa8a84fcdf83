"""The sync plug-in protocol, and loading an implementation by short name or ``module:attribute``.

A sync implementation is a *factory*: any callable that takes one argument, the
:class:`~conformance.world.World` of a freshly built scene, and returns a callable with no
arguments. The kit calls the factory once per scene run, then calls what it returned once right
away (frame 0, before any step) and once after every ``p.stepSimulation()``. A class whose
``__init__`` takes the world and whose ``__call__`` takes nothing is such a factory::

    class MySync:
        def __init__(self, world):       # once per scene: keep what you need
            self.world = world
        def __call__(self):              # after every step: move world.targets to pybullet's poses
            ...

The kit never reads an implementation's state: it judges only what the actors draw.
"""

from __future__ import annotations

import importlib
import inspect
import os
import sys
import traceback
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

from conformance.sync import journal
from conformance.sync import time_limit as limits
from conformance.errors import SyncLoadError, SyncProtocolError, SyncRaised, SyncTimedOut
from conformance.implementations import SHORT_NAMES
from conformance.validation import SYNC_ENV_VAR
from conformance.world import World

__all__ = ["ENV_VAR", "SHORT_NAMES", "Syncer", "SyncImplementation", "load"]

ENV_VAR = SYNC_ENV_VAR
_IMPORTLIB = os.path.dirname(importlib.__file__)



def _exception_line(exc: BaseException) -> str:
    return f"{type(exc).__name__}: {exc}".rstrip(": ")


def _user_location(exc: BaseException) -> str:
    """File and line of the innermost frame outside the kit, where the plug-in went wrong."""
    kit = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))  # conformance/, not only sync/
    frames = [
        f for f in traceback.extract_tb(exc.__traceback__)
        if not f.filename.startswith("<") and not os.path.abspath(f.filename).startswith((kit, _IMPORTLIB))
    ]
    if not frames:
        return ""
    f = frames[-1]
    return f" at {f.filename}:{f.lineno} ({f.name})"


@dataclass(frozen=True)
class SyncImplementation:
    """A loaded sync implementation: its spec as given, and its factory."""

    spec: str
    target: str  # the module:attribute it resolved to
    factory: Callable[[World], Callable[[], None]]
    #: seconds each call into the implementation may take (None or 0: no limit; :mod:`conformance.sync.time_limit`)
    time_limit: float | None = limits.DEFAULT

    @property
    def summary(self) -> str:
        doc = inspect.getdoc(self.factory) or ""
        return doc.strip().splitlines()[0] if doc.strip() else ""

    def start(self, world: World) -> "Syncer":
        """Call the factory for ``world``; errors become :class:`~conformance.errors.SyncError`."""
        journal.check_not_crashed(self.spec, world.scene)
        journal.at(world.scene, None)
        try:
            with limits.limited(self.time_limit):
                step_fn = self.factory(world)
        except limits.Expired as exc:
            raise _timed_out(self.spec, self.time_limit, f"while being set up for scene {world.scene!r}", exc) from None
        except Exception as exc:
            raise SyncRaised(
                f"sync implementation {self.spec!r} raised while being set up for scene {world.scene!r}: "
                f"{_exception_line(exc)}{_user_location(exc)}."
            ) from exc
        finally:
            journal.returned()
        if not callable(step_fn):
            raise SyncProtocolError(
                f"sync implementation {self.spec!r} returned {step_fn!r} (type {type(step_fn).__name__}) for scene "
                f"{world.scene!r}, but should return a callable taking no arguments, which the kit calls after every "
                "step (see 'The sync protocol' in the README)."
            )
        _check_arity(step_fn, 0, f"the callable returned by sync implementation {self.spec!r}")
        return Syncer(self.spec, world.scene, step_fn, self.time_limit)


def _timed_out(spec: str, seconds: float, when: str, exc: BaseException) -> SyncTimedOut:
    return SyncTimedOut(
        f"sync implementation {spec!r} did not return within {seconds:g} s {when}, and was stopped there (the "
        f"limit of one call: --conformance-sync-timeout or the ini conformance_sync_timeout, 0 for none). "
        f"It was at:\n{limits.stack(exc)}")


class Syncer:
    """One implementation bound to one scene; calling it syncs one frame, within ``time_limit`` seconds."""

    def __init__(self, spec: str, scene: str, step_fn: Callable[[], None], time_limit: float | None = None):
        self.spec, self.scene, self._fn, self.time_limit = spec, scene, step_fn, time_limit
        self.frame = -1

    def __call__(self, frame: int) -> None:
        self.frame = frame
        journal.at(self.scene, frame)
        try:
            with limits.limited(self.time_limit):
                self._fn()
        except limits.Expired as exc:
            raise _timed_out(self.spec, self.time_limit, f"on scene {self.scene!r} at step {frame}", exc) from None
        except Exception as exc:
            raise SyncRaised(
                f"sync implementation {self.spec!r} raised on scene {self.scene!r} at step {frame}: "
                f"{_exception_line(exc)}{_user_location(exc)}."
            ) from exc
        finally:
            journal.returned()


def _check_arity(fn: Any, n: int, what: str) -> None:
    try:
        signature = inspect.signature(fn)
    except (TypeError, ValueError):  # builtins without a signature: let the call decide
        return
    try:
        signature.bind(*([None] * n))
    except TypeError:
        wanted = "one argument, the World" if n == 1 else "no arguments"
        raise SyncProtocolError(
            f"{what} has signature {signature}, but the kit calls it with {wanted} "
            "(see 'The sync protocol' in the README)."
        ) from None


def load(spec: str) -> SyncImplementation:
    """Load the implementation named by ``spec``: a short name (:data:`SHORT_NAMES`) or ``module:attribute``."""
    if not isinstance(spec, str) or not spec.strip():
        raise SyncLoadError(f"sync={spec!r} ({type(spec).__name__}), but should be a short name or 'module:attribute'.")
    spec = spec.strip()
    target = SHORT_NAMES.get(spec, spec)
    module_name, sep, attribute = target.partition(":")
    if not sep or not module_name or not attribute:
        raise SyncLoadError(
            f"sync={spec!r} is neither a short name ({', '.join(SHORT_NAMES)}) nor of the form 'module:attribute' "
            "(e.g. 'my_package.my_sync:MySync')."
        )
    if "" not in sys.path and os.getcwd() not in sys.path:
        # Like `python -m`, find the user's module in the directory the run started from.
        sys.path.insert(0, os.getcwd())
    try:
        module = importlib.import_module(module_name)
    except Exception as exc:
        hint = " Is it on PYTHONPATH, or in the directory you run from?" if isinstance(exc, ModuleNotFoundError) else ""
        if module_name.endswith(".py") or "/" in module_name or os.sep in module_name:
            # --scenes takes a file's path; --sync takes a module's name, as Python imports it.
            dotted = module_name.removesuffix(".py").replace(os.sep, ".").replace("/", ".").strip(".")
            relative = not os.path.isabs(module_name)
            top = module_name.replace(os.sep, "/").split("/")[0] if relative else ""
            hint = (" --sync takes a module's dotted name, not a file's path: "
                    + (f"'{dotted}:{attribute}', run from the directory that holds {top!r}." if relative else
                       f"'{Path(module_name).stem}:{attribute}' with {str(Path(module_name).parent)!r} on PYTHONPATH "
                       "(or run from there)."))
        raise SyncLoadError(
            f"sync implementation {spec!r}: importing module {module_name!r} failed with "
            f"{_exception_line(exc)}{_user_location(exc)}.{hint}"
        ) from exc
    obj: Any = module
    for part in attribute.split("."):
        try:
            obj = getattr(obj, part)
        except AttributeError:
            public = sorted(n for n in dir(module) if not n.startswith("_"))
            raise SyncLoadError(
                f"sync implementation {spec!r}: module {module_name!r} has no attribute {attribute!r}; "
                f"it defines {', '.join(public[:12]) or 'nothing public'}{' …' if len(public) > 12 else ''}."
            ) from None
    if not callable(obj):
        raise SyncProtocolError(
            f"sync implementation {spec!r} is {obj!r} (type {type(obj).__name__}), but should be a callable that "
            "takes the World and returns the per-step sync callable (see 'The sync protocol' in the README)."
        )
    _check_arity(obj, 1, f"sync implementation {spec!r}")
    return SyncImplementation(spec=spec, target=target, factory=obj)
