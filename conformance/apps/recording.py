"""What the kit saw of an app, tick by tick: the one thing the app's process hands back to the kit.

Index 0 of every per-tick array is the moment the kit took over the app's loop (the app built its
bodies and actors; no callback has run yet); index ``k`` is the end of the app's ``k``-th tick, which
is what its window draws next. A recording is plain numpy and JSON, so the judgement
(:mod:`conformance.apps.judge`) needs neither FURY nor pybullet and is tested on recordings made by hand.
"""

from __future__ import annotations

import io
import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from conformance.apps.bodies import Frame
from conformance.files import write_atomically

__all__ = ["ActorTrack", "Recording", "load", "save", "vertex_ranges"]


@dataclass
class ActorTrack:
    """One drawn actor: world vertices ``(T+1, n, 3)`` as the renderer draws them (through the actor's
    full matrix), its stored normals as lit ``(T+1, n, 3)`` or None, and per tick whether its vertex
    data changed and whether a change was announced to the renderer (VTK ``Modified()``, pygfx
    ``update_range``/``update_full``); ``missed`` lists the ticks whose change will not all reach the
    screen, with which buffer and vertices in words (pygfx uploads only the announced ranges of each
    buffer, so a change announced on positions alone, or outside its ranges, is missed too)."""

    label: str
    kind: str
    vertices: np.ndarray
    normals: np.ndarray | None
    changed: np.ndarray
    announced: np.ndarray
    missed: list = field(default_factory=list)  # (tick, "its normals changed at vertices 0–287, …")
    #: an actor a shader draws as spheres (FURY 2's impostor spheres): each vertex's sphere radius in world
    #: units, as first recorded; None for an actor whose triangles are what it draws
    radii: np.ndarray | None = None


@dataclass
class Recording:
    """An app's run under the kit: its actors, its frames (every base and link on its clients) with
    their link-frame poses after each tick and just before each tick's last ``stepSimulation``, the
    steps per tick, and how the loop was taken over."""

    script: str
    backend: str
    actors: list[ActorTrack]
    frames: list[Frame]
    positions: np.ndarray       # (T+1, F, 3) link frames at the end of each tick
    orientations: np.ndarray    # (T+1, F, 4)
    before_positions: np.ndarray     # (T+1, F, 3) link frames just before the tick's last step
    before_orientations: np.ndarray
    steps: np.ndarray           # (T+1,) stepSimulation calls in each tick (index 0: 0)
    loop: str = ""              # how the kit drove the app, in words
    ended: str = ""             # why the loop ended
    events: list = field(default_factory=list)
    notes: list = field(default_factory=list)
    error: str = ""             # the app raised inside its loop: what and where
    #: seconds spent in the app's own ticks (its callbacks: steps, sync, render) and in the kit's reads
    #: and records around them, over the whole run (the cost benchmark's figures)
    seconds: dict = field(default_factory=dict)
    #: (T+1, F, 26) where the app wrote to pyBullet after a tick's last step: each frame's position,
    #: quaternion and velocities just before the first write, then the same at the end of the tick
    #: (NaN in ticks without such a write); None in recordings made without it
    writes: np.ndarray | None = None
    writers: list = field(default_factory=list)  # per tick, the names of the writing calls
    #: the app's mapping (:mod:`conformance.apps.mapping`): {"actor", "start", "stop", "frame"} entries
    mapping: list = field(default_factory=list)
    #: the pictures taken during the run (:func:`conformance.apps.picture.take`, at
    #: :func:`~conformance.apps.picture.picture_ticks`): dicts whose
    #: array values are numpy arrays
    pictures: list = field(default_factory=list)

    @property
    def ticks(self) -> int:
        return len(self.steps) - 1


def save(recording: Recording, path) -> None:
    """Write ``recording`` to ``path`` (an ``.npz``), whole or not at all."""
    arrays = {"positions": recording.positions, "orientations": recording.orientations,
              "before_positions": recording.before_positions, "before_orientations": recording.before_orientations,
              "steps": recording.steps}
    if recording.writes is not None:
        arrays["writes"] = recording.writes
    actors = []
    for i, track in enumerate(recording.actors):
        arrays[f"a{i}_vertices"] = track.vertices
        arrays[f"a{i}_changed"] = track.changed
        arrays[f"a{i}_announced"] = track.announced
        if track.normals is not None:
            arrays[f"a{i}_normals"] = track.normals
        if track.radii is not None:
            arrays[f"a{i}_radii"] = track.radii
        actors.append({"label": track.label, "kind": track.kind, "normals": track.normals is not None,
                       "missed": [list(m) for m in track.missed]})
    meta = {"script": recording.script, "backend": recording.backend, "actors": actors,
            "frames": [f.as_dict() for f in recording.frames], "loop": recording.loop, "ended": recording.ended,
            "events": recording.events, "notes": recording.notes,
            "error": recording.error, "seconds": recording.seconds, "writers": recording.writers,
            "mapping": recording.mapping}
    pictures = []
    for i, shot in enumerate(recording.pictures):
        plain = {}
        for key, value in shot.items():
            if isinstance(value, np.ndarray):
                arrays[f"p{i}_{key}"] = value
                plain.setdefault("arrays", []).append(key)
            else:
                plain[key] = value
        pictures.append(plain)
    meta["pictures"] = pictures
    arrays["meta"] = np.frombuffer(json.dumps(meta).encode("utf-8"), dtype=np.uint8)
    buffer = io.BytesIO()
    np.savez(buffer, **arrays)
    write_atomically(Path(path), buffer.getvalue())


def _frame(d: dict) -> Frame:
    shapes = tuple((s[0], tuple(s[1]), tuple(s[2]), tuple(s[3])) for s in d["shapes"])
    return Frame(d["client"], d["body"], d["link"], d["name"], d["mass"], shapes, tuple(d.get("inertial", (0.0, 0.0, 0.0))),
                 tuple(tuple(v) for v in d.get("mesh", ())),
                 tuple((v[0], tuple(v[1]), tuple(v[2]), tuple(v[3]), tuple(tuple(q) for q in v[4])) for v in d.get("visuals", ())), d.get("node", -1),
                 d.get("shown", -1), tuple(d.get("inertial_turn", (0.0, 0.0, 0.0, 1.0))))


def load(path) -> Recording:
    with np.load(path) as data:
        meta = json.loads(bytes(data["meta"]).decode("utf-8"))
        pictures = []
        for i, plain in enumerate(meta.get("pictures", [])):
            shot = {k: v for k, v in plain.items() if k != "arrays"}
            shot.update({key: data[f"p{i}_{key}"] for key in plain.get("arrays", [])})
            pictures.append(shot)
        actors = []
        for i, a in enumerate(meta["actors"]):
            actors.append(ActorTrack(a["label"], a["kind"], data[f"a{i}_vertices"],
                                     data[f"a{i}_normals"] if a["normals"] else None,
                                     data[f"a{i}_changed"], data[f"a{i}_announced"],
                                     [(int(t), str(text)) for t, text in a.get("missed", [])],
                                     data[f"a{i}_radii"] if f"a{i}_radii" in data else None))
        return Recording(meta["script"], meta["backend"], actors, [_frame(f) for f in meta["frames"]],
                         data["positions"], data["orientations"], data["before_positions"],
                         data["before_orientations"], data["steps"], meta["loop"], meta["ended"],
                         meta["events"], meta["notes"], meta.get("error", ""),
                         meta.get("seconds", {}), data["writes"] if "writes" in data else None,
                         meta.get("writers", []), mapping=meta.get("mapping", []), pictures=pictures)


def vertex_ranges(rows: np.ndarray, most: int = 3) -> str:
    """Sorted vertex indices as the ranges they make: ``0:24``, ``0:3, 40:64``, ``0:3, 8:9, 12:20 and 4
    more ranges`` (a frame may hold scattered vertices of an actor; one range over them would claim the
    vertices between)."""
    rows = np.asarray(rows)
    if not len(rows):
        return "none"
    breaks = np.flatnonzero(np.diff(rows) != 1) + 1
    starts, stops = np.concatenate([[0], breaks]), np.concatenate([breaks, [len(rows)]])
    spans = [f"{rows[a]}:{rows[b - 1] + 1}" for a, b in zip(starts, stops)]
    more = len(spans) - most
    return ", ".join(spans[:most]) + (f" and {more} more range{'s' if more > 1 else ''}" if more > 0 else "")
