"""The verdicts on an app's recording: one per check, each with what failed, where, and why.

Checks (the names are the pytest ids and the ``app`` command's lines):

* ``runs``: the app ran its loop without raising, and stepped;
* ``attached``: every drawn vertex is held by the link frame of one body or link, or by the world, at
  every tick (:mod:`conformance.apps.attachment`);
* ``drawn``: every frame pyBullet moves, that has a collision shape, is followed by some vertices;
* ``placed``: a drawing whose shape is its frame's collision shape sits on it (:mod:`conformance.apps.placement`);
* ``normals``: stored vertex normals turn with the frame that holds their vertices;
* ``announced``: every change of an actor's vertex data was announced to the renderer at the tick it was made.

Everything is computed from the :class:`~conformance.apps.recording.Recording` alone.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.spatial.transform import Rotation

from conformance.apps import attachment as attach_mod
from conformance.apps.placement import bounding_radius, place
from conformance.apps.recording import Recording
from conformance.tolerances import DEFAULT, Tolerance

__all__ = ["CHECKS", "DIAGNOSES", "Verdict", "judge"]

CHECKS = ("runs", "attached", "drawn", "placed", "normals", "announced")

#: diagnosis id → what it means, for the docs and every failure line
DIAGNOSES = {name: text for name, (text, _) in attach_mod.VARIANTS.items()} | {
    "com-frame": "drawn at the centre-of-mass frame (getBasePositionAndOrientation, or getLinkState()[0:2]) instead "
                 "of the link frame: undo getDynamicsInfo(body, link)[3:5], or read getLinkState()[4:6]",
    "never-moved": "left where it was built while its body moves: the sync never sets this actor (or this range)",
    "other-body": "follows another body's frame: the vertex range or the actor was paired with the wrong body",
    "turned-shape": "the actor was built turned in its body's frame (a box's directions, a cylinder's axis)",
    "stale-normals": "the vertices turn but the stored normals do not: turn normals with the same rotation",
    "unannounced": "vertex data changed without telling the renderer, which keeps drawing the old data: call "
                   "utils.update_actor (FURY 0.12) or positions.update_range/update_full (FURY 2)",
}


@dataclass
class Verdict:
    check: str
    passed: bool
    lines: list = field(default_factory=list)
    diagnoses: list = field(default_factory=list)
    worst: float | None = None      # worst error / allowance, where the check measures one
    notes: list = field(default_factory=list)

    def message(self) -> str:
        return "\n".join(self.lines)


def _rotations(q: np.ndarray) -> np.ndarray:
    return Rotation.from_quat(q.reshape(-1, 4)).as_matrix().reshape(q.shape[:-1] + (3, 3))


class _Judgement:
    def __init__(self, recording: Recording, tolerance: Tolerance):
        self.r, self.tolerance = recording, tolerance
        self.pos = recording.positions[1:]
        self.orn = recording.orientations[1:]
        self.rot = _rotations(self.orn) if self.orn.size else np.zeros(self.orn.shape[:-1] + (3, 3))
        self.event_ticks = sorted({int(e["frame"]) - 1 for e in recording.events})
        self.attachments = [attach_mod.attach(a.vertices[1:], self.pos, self.rot, tolerance=tolerance,
                                              event_ticks=self.event_ticks) for a in recording.actors] \
            if recording.ticks else []
        self.followed_badly: set[int] = set()
        self._attached_done = False

    def frame_label(self, index: int) -> str:
        return "the world" if index < 0 else self.r.frames[index].label

    # -- checks ----------------------------------------------------------------------------------
    def runs(self) -> Verdict:
        lines = []
        if self.r.error:
            lines.append(self.r.error.strip())
        if self.r.ticks == 0:
            lines.append("the app's loop ran no tick")
        elif not self.r.steps[1:].any():
            lines.append(f"the app never called p.stepSimulation() in {self.r.ticks} ticks")
        return Verdict("runs", not lines, lines)

    def attached(self) -> Verdict:
        self._attached_done = True
        self.followed_badly.clear()
        verdict = Verdict("attached", True)
        worst = 0.0
        for track, a in zip(self.r.actors, self.attachments):
            ratio = a.error / a.allowance[:, None]
            worst = max(worst, float(ratio.max(initial=0)))
            loose = ~a.held
            tied = int(a.tied.sum())
            if tied:
                verdict.notes.append(f"{track.label}: {tied} vertices are held equally by two frames that never moved "
                                     "apart in this run (undecidable; the kit's perturbed runs move bodies apart)")
            for start, stop in _runs(loose, np.zeros(len(loose), dtype=int)):
                verdict.passed = False
                rows = np.arange(start, stop)
                frame, diagnosis = self._followed(track.vertices[1:, rows], a.frame[rows], a.reference[rows])
                error, allowance = self._errors(track.vertices[1:, rows], frame)
                bad_ticks = np.flatnonzero(np.any(error > allowance[:, None], axis=0))
                first = int(bad_ticks[0]) if len(bad_ticks) else 0
                k = int(np.argmax(error.max(axis=0)))
                self.followed_badly.add(frame)
                verdict.lines.append(
                    f"{track.label} ({track.kind}) vertices {start}:{stop} of {len(a.frame)}: not held by any frame; "
                    f"follows {self.frame_label(frame)} best, and left it at tick {first + 1}: "
                    f"{error[:, first].max():.3g} m from where that frame carries it (allowed "
                    f"{allowance.max():.3g} m); worst {error[:, k].max():.3g} m at tick {k + 1}")
                if diagnosis:
                    verdict.lines.append(f"    diagnosis: {DIAGNOSES[diagnosis]}")
                    verdict.diagnoses.append(diagnosis)
        verdict.worst = worst
        return verdict

    def _followed(self, vertices, best, reference) -> tuple[int, str]:
        """The frame a run of loose vertices follows, and the mistake that explains it if one does: of
        the frames its vertices came nearest to being held by and the four frames nearest to the run,
        the first whose pose under a known mistake holds the run; else the one with the smallest median
        error (the world only when no body does better)."""
        centre = vertices[0].mean(axis=0)
        nearest = np.argsort(np.linalg.norm(self.pos[0] - centre, axis=1))[:4] if self.pos.shape[1] else []
        candidates = list(dict.fromkeys([int(f) for f in np.unique(best) if f >= 0] + [int(f) for f in nearest]))
        scored = []
        for frame in candidates:
            error, allowance = self._errors(vertices, frame)
            bad_ticks = np.flatnonzero(np.any(error > allowance[:, None], axis=0))
            diagnosis = self._diagnose(vertices, frame, reference, allowance, bad_ticks)
            if diagnosis:
                return frame, diagnosis
            scored.append((float(np.median(error)), frame))
        world, _ = self._errors(vertices, -1)
        scored.append((float(np.median(world)) + 1e-12, -1))
        return min(scored)[1], ""

    def _errors(self, vertices, frame: int):
        """Error ``(m, T)`` and allowance ``(m,)`` of vertices ``(T, m, 3)`` held by ``frame``."""
        m = vertices.shape[1]
        pos, rot = attach_mod._world(self.pos, self.rot)
        f = np.full(m, frame if frame >= 0 else pos.shape[1] - 1)
        local = attach_mod.local_coordinates(vertices, pos[:, f], rot[:, f])
        error = np.linalg.norm(local - np.median(local, axis=0), axis=-1).T
        return error, attach_mod._allowance(vertices, pos, rot, f, self.tolerance)

    def _diagnose(self, vertices, frame, reference, allowance, bad_ticks) -> str:
        if frame < 0:
            return ""
        m = vertices.shape[1]
        f = np.full(m, frame)
        before_pos = self.r.before_positions[1:][:, f]
        before_orn = self.r.before_orientations[1:][:, f]
        for name, (_, make) in attach_mod.VARIANTS.items():
            positions, rotations = make(self.pos[:, f], self.orn[:, f], before_pos, before_orn)
            if attach_mod.variant_fit(vertices, np.asarray(positions), np.asarray(rotations), reference,
                                      allowance, bad_ticks):
                return name
        return ""

    def drawn(self) -> Verdict:
        if not self._attached_done:
            self.attached()
        verdict = Verdict("drawn", True)
        followed = set(self.followed_badly)  # loose vertices that follow a frame are the attached check's
        for a in self.attachments:
            followed.update(int(f) for f in np.unique(a.frame[a.held]) if f >= 0)
        for index, frame in enumerate(self.r.frames):
            if index in followed or not frame.shapes:
                continue
            moved = self._movement(index, bounding_radius(frame.shapes))
            allowance = 10 * self.tolerance.for_extents(np.array([bounding_radius(frame.shapes)]),
                                                        self.pos[:1, index])[0] if self.r.ticks else 0
            if moved <= allowance:
                continue
            verdict.passed = False
            line = (f"{frame.label} moves ({moved:.3g} m over ticks 1..{self.r.ticks}) but no drawn vertex follows it")
            near = self._left_behind(index)
            verdict.lines.append(line + (f"; {near} stays where it was built" if near else ""))
            if near:
                verdict.lines.append(f"    diagnosis: {DIAGNOSES['never-moved']}")
                verdict.diagnoses.append("never-moved")
        return verdict

    def _movement(self, index: int, radius: float) -> float:
        if self.r.ticks == 0:
            return 0.0
        p = self.r.positions[:, index]
        turn = (Rotation.from_quat(self.r.orientations[:, index]) * Rotation.from_quat(self.r.orientations[0, index]).inv()).magnitude()
        return float(max(np.max(np.linalg.norm(p - p[0], axis=1)), np.max(turn) * radius))

    def _left_behind(self, index: int) -> str:
        """An actor range held by the world that sits on this frame as it was at the start."""
        radius = bounding_radius(self.r.frames[index].shapes)
        # A frame that never moves holds what the world holds (a static ground plate): either may be named.
        still = [i for i, f in enumerate(self.r.frames) if self._movement(i, bounding_radius(f.shapes) if f.shapes else 0.0) == 0.0]
        for track, a in zip(self.r.actors, self.attachments):
            world = np.flatnonzero(((a.frame < 0) | np.isin(a.frame, still)) & a.held)
            if not len(world):
                continue
            for start, stop in _runs(np.isin(np.arange(len(a.frame)), world), a.frame):
                centre = track.vertices[0, start:stop].mean(axis=0)
                if np.linalg.norm(centre - self.r.positions[0, index]) <= radius + 0.01:
                    return f"{track.label} vertices {start}:{stop}"
        return ""

    def placed(self) -> Verdict:
        verdict = Verdict("placed", True)
        for track, a in zip(self.r.actors, self.attachments):
            for frame in np.unique(a.frame):
                if frame < 0:
                    continue
                rows = np.flatnonzero((a.frame == frame) & a.held)
                if not len(rows):
                    continue
                info = self.r.frames[frame]
                inertial = self._inertial(frame)
                result = place(a.reference[rows], info.shapes, inertial, tolerance=self.tolerance)
                where = f"{track.label} vertices {rows[0]}:{rows[-1] + 1} held by {info.label}"
                if not result.judged:
                    verdict.notes.append(f"{where}: {result.why}")
                elif not result.ok:
                    verdict.passed = False
                    diagnosis = result.diagnosis or self._other_body(result.offset, frame)
                    verdict.lines.append(f"{where}: {result.why}")
                    if diagnosis:
                        verdict.lines.append(f"    diagnosis: {DIAGNOSES[diagnosis]}")
                        verdict.diagnoses.append(diagnosis)
        return verdict

    def _inertial(self, frame: int) -> np.ndarray:
        return np.asarray(self.r.frames[frame].inertial, dtype=np.float64)

    def _other_body(self, offset, frame) -> str:
        return "other-body" if offset is not None and np.linalg.norm(offset) > bounding_radius(self.r.frames[frame].shapes) else ""

    def normals(self) -> Verdict:
        verdict = Verdict("normals", True)
        worst = 0.0
        for track, a in zip(self.r.actors, self.attachments):
            if track.normals is None:
                continue
            frames = a.frame
            rot = np.concatenate([self.rot, np.broadcast_to(np.eye(3), self.rot.shape[:1] + (1, 3, 3))], axis=1)
            local = np.einsum("tnji,tnj->tni", rot[:, frames], track.normals[1:])
            reference = np.median(local, axis=0)
            reference /= np.maximum(np.linalg.norm(reference, axis=1, keepdims=True), 1e-12)
            angle = np.arccos(np.clip(np.einsum("tni,ni->tn", local, reference), -1, 1))
            worst = max(worst, float(angle.max(initial=0)) / self.tolerance.normal_angle)
            bad = np.any(angle > self.tolerance.normal_angle, axis=0) & a.held
            for start, stop in _runs(bad, frames):
                verdict.passed = False
                first = int(np.flatnonzero(np.any(angle[:, start:stop] > self.tolerance.normal_angle, axis=1))[0])
                verdict.lines.append(f"{track.label} normals {start}:{stop}: do not turn with {self.frame_label(int(frames[start]))} "
                                     f"from tick {first + 1} ({np.degrees(angle[:, start:stop].max()):.3g}° off; allowed "
                                     f"{np.degrees(self.tolerance.normal_angle):.3g}°)")
                verdict.lines.append(f"    diagnosis: {DIAGNOSES['stale-normals']}")
                verdict.diagnoses.append("stale-normals")
        verdict.worst = worst
        return verdict

    def announced(self) -> Verdict:
        verdict = Verdict("announced", True)
        for track in self.r.actors:
            silent = np.flatnonzero(track.changed[1:] & ~track.announced[1:])
            if len(silent):
                verdict.passed = False
                verdict.lines.append(f"{track.label} ({track.kind}): its vertex data changed at tick {silent[0] + 1} "
                                     f"({len(silent)} ticks in all) without being announced to the renderer")
                verdict.lines.append(f"    diagnosis: {DIAGNOSES['unannounced']}")
                verdict.diagnoses.append("unannounced")
        return verdict


def _runs(mask: np.ndarray, frames: np.ndarray):
    """``(start, stop)`` of each run of consecutive true entries of ``mask`` with one frame."""
    start = None
    for i in range(len(mask) + 1):
        boundary = i == len(mask) or not mask[i] or (start is not None and frames[i] != frames[start])
        if start is not None and boundary:
            yield start, i
            start = None
        if i < len(mask) and mask[i] and start is None:
            start = i


def judge(recording: Recording, *, tolerance: Tolerance = DEFAULT, checks=CHECKS) -> dict[str, Verdict]:
    """Every check of ``checks`` on ``recording``."""
    judgement = _Judgement(recording, tolerance)
    verdicts = {}
    for check in checks:
        if recording.ticks == 0 and check != "runs":
            verdicts[check] = Verdict(check, False, ["the app's loop ran no tick: nothing was drawn to judge"])
            continue
        verdicts[check] = getattr(judgement, check)()
    return verdicts
