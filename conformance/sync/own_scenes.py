"""Your own scenes beside the kit's: where they are loaded from, and where their goldens live.

A *scene source* is a Python file (``my_scenes.py``, ``tests/scenes/robot.py``) or an importable
module (``myproject.scenes``) that defines :class:`~conformance.scenes.SceneSpec` objects at module
level (or calls :func:`~conformance.scenes.register` itself). Every command and the pytest plugin
load the sources named in, all together:

* ``--scenes SOURCE`` on any ``python -m conformance`` command (repeatable);
* ``--conformance-scenes SOURCE`` / ini ``conformance_scenes`` (one per line; paths relative to the
  ini file) under pytest;
* ``$CONFORMANCE_SCENES`` (sources separated by commas or ``os.pathsep``), which the command line also
  sets for the processes it starts (``run``, ``verdicts``, …), so they see the same scenes;
* the ``conformance.scenes`` entry point group, for a package that ships scenes.

A file is imported under its own name with its directory put first on ``sys.path``, so a fresh
process (the determinism check's) imports it again the same way. Loading is idempotent.

Goldens live per source: a kit scene's in the kit's ``golden/<backend>/``, a user's in
``golden/<backend>/`` beside the file that defines its ``populate`` function — so one run checks
the kit's scenes and yours, each against its own goldens. ``--conformance-golden-dir`` /
``regen --golden-dir`` still put every scene's goldens in one directory when given.
"""

from __future__ import annotations

import importlib
import importlib.metadata as md
import inspect
import os
import re
import sys
from pathlib import Path
from typing import Iterable

from conformance.errors import BadArgument

__all__ = ["ENTRY_POINTS", "ENV", "default_dir", "golden_dir", "load", "load_all", "scene_arguments", "source_of", "sources_from"]

ENV = "CONFORMANCE_SCENES"
ENTRY_POINTS = "conformance.scenes"


def sources_from(text: str | None) -> list[str]:
    """The sources listed in ``$CONFORMANCE_SCENES``-style text (commas, ``os.pathsep`` or newlines)."""
    return [part.strip() for part in re.split(rf"[,\n{re.escape(os.pathsep)}]", text or "") if part.strip()]


def _is_path(source: str) -> bool:
    return source.endswith(".py") or os.sep in source or "/" in source


def _import_file(source: str, relative_to: Path) -> object:
    path = (relative_to / source).resolve()
    if not path.is_file():
        raise BadArgument(f"scene source {source!r}: {path} is not a file. Give a Python file that defines "
                          "SceneSpec objects, or an importable module name (e.g. myproject.scenes)")
    if path.suffix != ".py" or not path.stem.isidentifier():
        raise BadArgument(f"scene source {source!r}: {path.name} cannot be imported as a module; name the file "
                          "like a Python module, e.g. my_scenes.py")
    folder = str(path.parent)
    if folder not in sys.path:
        sys.path.insert(0, folder)
    module = _import_module(path.stem, source)
    found = Path(getattr(module, "__file__", "") or "").resolve()
    if found != path:
        raise BadArgument(f"scene source {source!r}: importing it as {path.stem!r} found another module, {found}; "
                          "rename the file so its name is not already taken by an installed module")
    return module


def _import_module(name: str, source: str) -> object:
    try:
        return importlib.import_module(name)
    except ModuleNotFoundError as exc:
        if exc.name and name.startswith(exc.name):
            raise BadArgument(f"scene source {source!r}: no module {exc.name!r} on sys.path (run from the directory "
                              "that holds it, or give the path of the .py file)") from None
        raise BadArgument(f"scene source {source!r} could not be imported: it imports {exc.name!r}, "
                          "which is not installed here") from None
    except Exception as exc:  # the user's module is broken: say where, keep the kit's traceback out
        where = ""
        tb = exc.__traceback__
        while tb is not None:
            if tb.tb_frame.f_code.co_filename.endswith(".py"):
                where = f" ({tb.tb_frame.f_code.co_filename}, line {tb.tb_lineno})"
            tb = tb.tb_next
        raise BadArgument(f"scene source {source!r} raised {type(exc).__name__} while being imported{where}: {exc}") from None


def load(source: str, *, relative_to: Path | str | None = None) -> list[str]:
    """Import one scene source and register every SceneSpec it defines; return their names."""
    from conformance import scenes

    if not isinstance(source, str) or not source.strip():
        raise BadArgument(f"scene source={source!r} ({type(source).__name__}), but should be a .py file or a module name")
    before = dict(scenes.SCENES)
    if _is_path(source):
        module = _import_file(source, Path(relative_to or Path.cwd()))
    else:
        module = _import_module(source, source)
    for value in list(vars(module).values()):
        if isinstance(value, scenes.SceneSpec):
            known = scenes.SCENES.get(value.name)
            if known is None:
                scenes.register(value)
            elif known is not value and not _same(known, value):
                raise BadArgument(f"scene source {source!r} defines scene {value.name!r}, but a scene of that name "
                                  f"is already registered (from {source_of(value.name) or 'the kit'}); rename yours")
    names = [name for name, spec in scenes.SCENES.items()
             if name not in before or _module_of(spec) == getattr(module, "__name__", None)]
    if not names:
        raise BadArgument(f"scene source {source!r} ({getattr(module, '__file__', module)}) defines no SceneSpec; "
                          "give it one at module level, e.g. SPEC = SceneSpec(name='my_scene', …)")
    # What loaded them, as it can be given again: the file for a path, the module's name for a module (a
    # package's module re-imported as a file would lose its relative imports).
    file = str(Path(module.__file__).resolve()) if getattr(module, "__file__", None) else None
    given = file if _is_path(source) and file else source
    for name in names:
        _LOADED_FROM.setdefault(name, (given, file))
    return names


#: Each own scene's source as it was loaded (``load``): what a printed command gives ``--scenes``, and
#: the file it is (beside which the scene's goldens live).
_LOADED_FROM: dict[str, tuple[str, str | None]] = {}


def _module_of(spec) -> str | None:
    return getattr(spec.populate, "__module__", None)


def _same(a, b) -> bool:
    # The same file imported twice (e.g. once by name, once by path) defines equal specs.
    return a.name == b.name and getattr(a.populate, "__qualname__", 0) == getattr(b.populate, "__qualname__", 1) and \
        inspect.getsourcefile(a.populate) == inspect.getsourcefile(b.populate)


def load_all(given: Iterable[str] = (), *, relative_to: Path | str | None = None, environment: bool = True) -> list[str]:
    """Load ``given`` sources, then ``$CONFORMANCE_SCENES`` and the entry points; return the names loaded."""
    names: list[str] = []
    for source in given:
        names += load(source, relative_to=relative_to)
    if environment:
        for source in sources_from(os.environ.get(ENV)):
            names += load(source)
        for entry in md.entry_points(group=ENTRY_POINTS):
            names += load(entry.value.split(":")[0])
    return list(dict.fromkeys(names))


def export(given: Iterable[str], *, relative_to: Path | str | None = None) -> None:
    """Put ``given`` (as absolute paths where they are files) into ``$CONFORMANCE_SCENES`` for the
    processes this one starts."""
    base = Path(relative_to or Path.cwd())
    absolute = [str((base / s).resolve()) if _is_path(s) else s for s in given]
    current = sources_from(os.environ.get(ENV))
    merged = list(dict.fromkeys(current + absolute))
    if merged:
        os.environ[ENV] = ",".join(merged)


def source_of(name: str) -> str | None:
    """The scene source that registered scene ``name`` (the file or module given to ``--scenes``, the
    ini or ``$CONFORMANCE_SCENES``), else the file that defines its ``populate``; None for the kit's own
    scenes. Not ``populate``'s file first: a scene file may import its ``populate`` from a helper module,
    which defines no SceneSpec."""
    if name in _LOADED_FROM:
        return _LOADED_FROM[name][0]
    return _populate_file(name)


def _populate_file(name: str) -> str | None:
    from conformance import scenes

    populate = scenes.get(name).populate
    if (getattr(populate, "__module__", "") or "").startswith(scenes.__name__ + "."):
        return None  # the kit's (in a checkout and in a wheel alike: the package conformance.scenes)
    try:
        return str(Path(inspect.getsourcefile(populate) or "").resolve())
    except TypeError:  # a builtin or C function: nothing to point at
        return None


def scene_arguments(name: str) -> list[str]:
    """What a command line needs to see scene ``name``: ``["--scenes", FILE]`` for a user's scene."""
    source = source_of(name)
    if source is None:
        return []
    if not _is_path(source):
        return ["--scenes", source]  # a module's name, as it was given
    try:
        source = os.path.relpath(source)
    except ValueError:  # another drive (Windows)
        pass
    return ["--scenes", source]


def default_dir() -> Path:
    """The goldens shipped with the kit for the backend in force: ``golden/<backend>/`` in a checkout,
    ``conformance/golden/<backend>/`` in a wheel (renderers differ, so each backend has its own)."""
    from conformance import backends

    return Path(__file__).resolve().parent.parent / "golden" / backends.NAME  # conformance/golden


def golden_dir(name: str) -> Path:
    """Where scene ``name``'s goldens live when no golden directory is given: the kit's own for its
    scenes, ``golden/<backend>/`` beside the user's file for theirs."""
    from conformance import backends

    if source_of(name) is None:
        return default_dir()
    file = _LOADED_FROM[name][1] if name in _LOADED_FROM else None
    return Path(file or _populate_file(name) or ".").parent / "golden" / backends.NAME
