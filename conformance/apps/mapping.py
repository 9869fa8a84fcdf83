"""An app's mapping, optional: which body or link each actor (or vertex range of one) draws.

Without it the kit finds the frame that holds each vertex (:mod:`conformance.apps.attachment`); with
it the judgement is exact: the mapped vertices must be held by *the* frame named, not by any, and two
bodies that never move apart are no longer undecidable. The mapping lives beside the app, never in it:
for ``my_sim.py`` a file ``my_sim.mapping.py`` in the same directory, found by the kit on every run
(``app``, the pytest checks, the perturbed runs). It defines ``mapping(app)``, called once the app
has built its bodies and actors (when the kit takes over its loop) with the app's module, and returns
:class:`Draws` entries::

    from conformance.apps.mapping import Draws

    def mapping(app):
        yield Draws(app.ball_actor, app.ball)
        for i, brick in enumerate(app.bricks):          # 24 vertices a brick in one shared actor
            yield Draws(app.brick_actor, int(brick), vertices=(24 * i, 24 * (i + 1)))

A mapping that cannot be used (it raises, names an actor the scene does not draw, a body or link the
app's client does not have, vertices the actor has not) stops the run with one paragraph naming the
entry, as a broken plug-in does.
"""

from __future__ import annotations

import importlib.util
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from conformance.errors import ConformanceError

__all__ = ["SUFFIX", "Draws", "MappingError", "path_for", "resolve"]

SUFFIX = ".mapping.py"


class MappingError(ConformanceError):
    """The app's mapping file cannot be used; the message names the file and the entry."""


@dataclass(frozen=True)
class Draws:
    """``actor`` draws ``body``'s ``link`` (-1: the base) with its vertices ``vertices`` = ``(start, stop)``
    (None: all of them), on pyBullet client ``client`` (None: the first of the app's clients that has
    bodies, so an app that keeps an empty client for probes need not name the one it simulates on)."""

    actor: Any
    body: int
    link: int = -1
    vertices: tuple[int, int] | None = None
    client: int | None = None


def path_for(script) -> Path:
    """Where the mapping of ``script`` lives: ``my_sim.mapping.py`` beside ``my_sim.py``."""
    script = Path(script)
    return script.with_name(script.stem + SUFFIX)


def resolve(script, app_module, actors, labels: dict[int, str], counts: list[int], frames, clients) -> list[dict]:
    """The mapping of ``script`` as ``{"actor", "start", "stop", "frame"}`` entries (indices into ``actors``,
    whose vertex ``counts`` are given, and ``frames``), or ``[]`` when the app has no mapping file."""
    path = path_for(script)
    if not path.is_file():
        return []
    try:
        spec = importlib.util.spec_from_file_location(f"_conformance_mapping_{abs(hash(str(path)))}", path)
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        function = getattr(module, "mapping", None)
        if not callable(function):
            raise MappingError(f"{path}: defines no function mapping(app); write one returning Draws(actor, body, "
                               "link=-1, vertices=None) entries (see docs/apps.md, 'A mapping')")
        entries = list(function(app_module))
    except MappingError:
        raise
    except Exception as exc:
        raise MappingError(f"{path}: the mapping raised {type(exc).__name__}: {exc}; fix it, or remove the file to "
                           "judge the app by attachment alone") from None
    by_actor = {id(a): i for i, a in enumerate(actors)}
    by_frame = {(f.client, f.body, f.link): j for j, f in enumerate(frames) if f.node < 0}
    with_bodies = [c for c in clients if any(f.client == c for f in frames)] or list(clients)
    resolved = []
    for n, entry in enumerate(entries):
        where = f"{path}: entry {n} ({entry!r})"
        if not isinstance(entry, Draws):
            raise MappingError(f"{where} is a {type(entry).__name__}, but should be a Draws(actor, body, link=-1, "
                               "vertices=None) from conformance.apps.mapping")
        index = by_actor.get(id(entry.actor))
        if index is None:
            raise MappingError(f"{where}: its actor is not one the ShowManager's scene draws "
                               f"({len(actors)} actors: {', '.join(labels.get(id(a), '?') for a in actors[:8])}…)")
        client = with_bodies[0] if entry.client is None else entry.client
        frame = by_frame.get((client, int(entry.body), int(entry.link)))
        if frame is None:
            raise MappingError(f"{where}: body {entry.body} link {entry.link} on client {client} does not exist "
                               f"(the app's frames: {', '.join(f.label for f in frames[:8])}…)")
        count = counts[index]
        start, stop = (0, count) if entry.vertices is None else (int(entry.vertices[0]), int(entry.vertices[1]))
        if not 0 <= start < stop <= count:
            raise MappingError(f"{where}: vertices=({start}, {stop}), but should lie within the actor's "
                               f"{count} vertices, start before stop")
        resolved.append({"actor": index, "start": start, "stop": stop, "frame": frame})
    return resolved

