"""The verdicts on an app's recording: one per check, each with what failed, where, and why.

Checks (the names are the pytest ids and the ``app`` command's lines):

* ``runs``: the app ran its loop without raising, and stepped;
* ``attached``: every drawn vertex is held by the link frame of one body or link, or by the world, at
  every tick (:mod:`conformance.apps.attachment`);
* ``drawn``: every frame pyBullet moves, that has a collision shape, is followed by some vertices;
* ``placed``: a drawing whose shape is its frame's collision shape sits on it (:mod:`conformance.apps.placement`);
* ``normals``: stored vertex normals turn with the frame that holds their vertices;
* ``announced``: every change of an actor's vertex data was announced to the renderer at the tick it was made;
* ``untouched``: after a tick's last ``stepSimulation`` — where the sync runs — the app never writes a body's own
  pose back into pyBullet (a sync only reads the simulation; the guide's recipes only read); a body it moves
  there on purpose (kinematic playback) is judged where pyBullet holds it when the app draws;
* ``pictured``: the app's pictures at four ticks of the run (the last at its end), from its own camera, show
  each body where pyBullet's own renderer shows it (:mod:`conformance.apps.pictured`).

Everything is computed from the :class:`~conformance.apps.recording.Recording` alone. The checks say what failed;
which mistake of the catalogue made it, :mod:`conformance.apps.naming` says.
"""

from __future__ import annotations

import functools

import numpy as np
from scipy.spatial.transform import Rotation

from conformance.apps import attachment as attach_mod, soft_bodies, surface_normals, welds
from conformance.apps.naming import UNTOUCHED_ATOL, Naming
from conformance.apps.verdict import DIAGNOSES, Verdict
from conformance.apps.placement import bounding_radius, bounding_sphere, candidates, place, shape_distance
from conformance.apps.recording import Recording, vertex_ranges
from conformance.judge.tolerances import DEFAULT, Tolerance

__all__ = ["CHECKS", "DIAGNOSES", "Verdict", "judge"]

CHECKS = ("runs", "attached", "drawn", "placed", "normals", "announced", "untouched", "pictured")

#: What `placed` names a drawing held by its frame but turned in it; a rotation mistake of the pose draws it so too
#: on a link that never turns (:meth:`_Judgement._turned_alike`)
TURNED_IN_ITS_FRAME = ("turned-shape", "visual-frame")
#: pyBullet's calls that set a pose (a write-back writes one): the driver's STATE_WRITERS but resetBaseVelocity
POSE_WRITERS = {"resetBasePositionAndOrientation", "resetJointState", "resetJointStateMultiDof", "resetJointStatesMultiDof"}


class _Judgement(Naming):
    def __init__(self, recording: Recording, tolerance: Tolerance):
        self.r, self.tolerance = recording, tolerance
        self.pos = recording.positions[1:]
        self.orn = recording.orientations[1:]
        self.rot = attach_mod.rotations(self.orn) if self.orn.size else np.zeros(self.orn.shape[:-1] + (3, 3))
        self.event_ticks = sorted({int(e["frame"]) - 1 for e in recording.events})
        self._distances: dict = {}  # frame -> its shape_distance, hulls computed once
        #: each frame's bounding sphere (centre in its link frame, radius): attachment's nearness, _radii's reach
        self._spheres = spheres = [bounding_sphere(f.shapes, f.mesh) for f in recording.frames]
        centres = np.array([c for c, _ in spheres]).reshape(-1, 3)
        radii = np.array([r for _, r in spheres])
        #: frames welded together (fixed joints): one rigid frame, whose vertices go to the member they lie on
        self.welds = welds.groups(recording.frames, recording.positions, attach_mod.rotations(recording.orientations)) \
            if recording.frames else np.zeros(0, int)
        #: per actor, its vertices that are not finite at some tick (NaN, infinity): drawn nowhere, judged by none
        #: of the checks but ``attached``, which fails them
        self.unfinite = [~np.isfinite(a.vertices[1:]).all(axis=(0, 2)) for a in recording.actors]
        self.attachments = [_attach_finite(a.vertices[1:], bad, self.pos, self.rot, tolerance=tolerance,
                                           event_ticks=self.event_ticks, centres=centres, radii=radii,
                                           groups=self.welds, outside=self._outside)
                            for a, bad in zip(recording.actors, self.unfinite)] \
            if recording.ticks else []
        self.mapped = [np.zeros(len(a.frame), dtype=bool) for a in self.attachments]
        for entry in recording.mapping:
            self._apply_mapping(entry)
        self.followed_badly: set[int] = set()
        self._attached_done = False
        self._placements = None
        #: per actor index, the vertices `drawn` found to be a moving frame's shape left where it was built
        self.left_behind: dict[int, set] = {}
        #: (client, body) of each soft body attached, drawn or placed found drawn wrong: its picture is then
        #: not evidence of its triangles (``face-order``)
        self.soft_misdrawn: set[tuple[int, int]] = set()
        self.placed_done = False
        #: frames `placed` found drawn off their shape or at another size, and those `drawn` found moving with no
        #: vertex following them: their picture is explained by that (:meth:`drawn_wrong`)
        self.misplaced: set[int] = set()
        self.undrawn: set[int] = set()
        self._drawn_verdict = None

    def _outside(self, frame: int, points: np.ndarray) -> np.ndarray:
        """How far link-frame ``points`` lie outside ``frame``'s collision and visual shapes (0 on or inside one)."""
        info = self.r.frames[frame]
        if info.node >= 0:  # a soft body's node is a point: a vertex drawn on it lies at its origin
            return np.linalg.norm(np.asarray(points, dtype=np.float64), axis=-1)
        if frame not in self._distances:
            self._distances[frame] = shape_distance(info.shapes, info.mesh, info.visuals)
        return self._distances[frame](points)

    def _apply_mapping(self, entry: dict) -> None:
        """Judge the mapped vertices in the frame the mapping names, not the one that holds them best:
        every later check (held, placed, drawn, normals) then reads the mapping's frame for them."""
        a, frame = self.attachments[entry["actor"]], int(entry["frame"])
        rows = slice(entry["start"], entry["stop"])
        vertices = self.r.actors[entry["actor"]].vertices[1:, rows]
        error, allowance = self._errors(vertices, frame)
        a.frame[rows], a.error[rows], a.allowance[rows], a.tied[rows] = frame, error, allowance, False
        a.reference[rows] = self._reference(vertices, frame)
        a.__dict__.pop("held", None)  # computed from the errors just replaced
        self.mapped[entry["actor"]][rows] = True

    def _reference(self, vertices, frame: int) -> np.ndarray:
        """Median coordinates ``(m, 3)`` of vertices ``(T, m, 3)`` in ``frame``."""
        pos, rot = self._with_world
        f = frame if frame >= 0 else pos.shape[1] - 1
        return np.median(attach_mod.local_coordinates(vertices, pos[:, f, None], rot[:, f, None]), axis=0)

    @functools.cached_property
    def _with_world(self) -> tuple[np.ndarray, np.ndarray]:
        """The frames' positions and rotations at the judged ticks, the world appended as the last frame."""
        return attach_mod._world(self.pos, self.rot)

    @functools.cached_property
    def _radii(self) -> np.ndarray:
        """How far each frame's collision shapes reach from its origin (0 for a frame without): a mesh's too (a
        Franka's links are meshes; measured by their box alone, every loose vertex of a link drawn with its
        quaternion reordered was diagnosed on its own, 12,847 pieces and most of the judgement's time)."""
        reach = [float(np.linalg.norm(c)) + r for c, r in self._spheres]
        return np.array([max(bounding_radius(f.shapes), far) if f.shapes else 0.0 for f, far in zip(self.r.frames, reach)])

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
        # What the kit changed in the app's run, or left out of it, is said under the check that ran it.
        return Verdict("runs", not lines, lines, notes=list(self.r.notes))

    def attached(self) -> Verdict:
        self._attached_done = True
        self.followed_badly.clear()
        verdict = Verdict("attached", True)
        worst = 0.0
        for index, (track, a, mapped) in enumerate(zip(self.r.actors, self.attachments, self.mapped)):
            ratio = np.max(a.error / a.allowance[:, None], axis=1, initial=0)
            loose = ~a.held & ~mapped
            tied = int(a.tied.sum())
            if tied:
                verdict.notes.append(f"{track.label}: {tied} vertices are held equally by two frames that never moved "
                                     "apart in this run (undecidable; the kit's perturbed runs move bodies apart)")
            soft: dict[tuple, list] = {}  # pieces that follow nodes of one soft body: one line for them all
            for start, stop, frame, diagnosis in self._loose_pieces(track, a, loose):
                rows = np.arange(start, stop)
                error, allowance = self._errors(track.vertices[1:, rows], frame)
                bad_ticks = attach_mod.bad_ticks(error, allowance)
                if not len(bad_ticks):
                    # The frame it follows holds it at every tick, within the allowance of the piece's own
                    # reach from that frame: held, and no line may say it left that frame at some tick.
                    ratio[rows] = np.max(error / allowance[:, None], axis=1)
                    continue
                verdict.passed = False
                first = int(bad_ticks[0])
                k = int(np.argmax(error.max(axis=0)))
                self.followed_badly.add(frame)
                info = self.r.frames[frame] if frame >= 0 else None
                if info is not None and info.node >= 0:
                    soft.setdefault((info.client, info.body, info.name, diagnosis), []).append(
                        soft_bodies.Piece(rows, error[:, first].max(), first, error[:, k].max(), k, allowance.max(), frame))
                    continue
                if diagnosis == "late-or-own-move":
                    verdict.ties.append((index, start, stop, frame))
                verdict.lines.append(
                    f"{track.label} ({track.kind}) vertices {start}:{stop} of {len(a.frame)}: not held by any frame; "
                    f"follows {self.frame_label(frame)} best, and left it at tick {first + 1}: "
                    f"{error[:, first].max():.3g} m from where that frame carries it (allowed "
                    f"{allowance.max():.3g} m); worst {error[:, k].max():.3g} m at tick {k + 1}")
                verdict.diagnosed(diagnosis)
            soft_bodies.attached(self, track, a, soft, verdict)
            worst = max(worst, float(ratio.max(initial=0)))
        for track, bad in zip(self.r.actors, self.unfinite):
            for start, stop in attach_mod.runs(bad, np.zeros(len(bad), dtype=int)):
                verdict.passed = False
                first = int(np.flatnonzero(~np.isfinite(track.vertices[:, start:stop]).all(axis=(1, 2)))[0])
                verdict.lines.append(
                    f"{track.label} ({track.kind}) vertices {start}:{stop} of {len(bad)}: not finite (NaN or infinity) "
                    f"at tick {first}: drawn nowhere, where pyBullet has a body or nothing (a zero-size shape normalised, "
                    "a division by zero, a value never set)")
        for entry in self.r.mapping:
            self._judge_mapped(entry, verdict)
        welded = sum(int(a.welded.sum()) for a in self.attachments if a.welded is not None)
        if welded:
            groups = {}
            for i, g in enumerate(self.welds):
                if g >= 0:
                    frame = self.r.frames[i]
                    name = f"{frame.name} node {frame.node}" if frame.node >= 0 else frame.name
                    groups.setdefault(int(g), []).append(name or self.frame_label(i))
            together = "; ".join(" + ".join(names) for names in groups.values())
            verdict.notes.append(f"{welded} vertices are held by frames welded together (fixed joints, or links that never "
                                 f"moved apart: {together}): each went to the frame whose shape it lies on")
        verdict.worst = worst
        return verdict

    def _judge_mapped(self, entry: dict, verdict: Verdict) -> None:
        """Mapped vertices are held by the very frame the mapping names at every tick."""
        track, a, frame = self.r.actors[entry["actor"]], self.attachments[entry["actor"]], int(entry["frame"])
        rows = np.arange(entry["start"], entry["stop"])
        if a.held[rows].all():
            return
        verdict.passed = False
        self.followed_badly.add(frame)
        error, allowance = a.error[rows], a.allowance[rows]
        bad_ticks = attach_mod.bad_ticks(error, allowance)
        first, k = int(bad_ticks[0]), int(np.argmax(error.max(axis=0)))
        vertices = track.vertices[1:, rows]
        diagnosis = self._diagnose(vertices, frame, a.reference[rows], allowance, bad_ticks)
        line = (f"{track.label} ({track.kind}) vertices {rows[0]}:{rows[-1] + 1}, drawn for {self.frame_label(frame)} "
                f"by the app's mapping: not held by it from tick {first + 1}: {error[:, first].max():.3g} m from where "
                f"it carries them (allowed {allowance.max():.3g} m); worst {error[:, k].max():.3g} m at tick {k + 1}")
        if not diagnosis:
            other, _ = self._followed(vertices, np.full(len(rows), -1), a.reference[rows])
            held, _ = self._errors(vertices, other)
            if other >= 0 and other != frame and np.all(held <= allowance[:, None]):
                line += f"; they are held by {self.frame_label(other)} instead"
                diagnosis = "other-body"
        if diagnosis == "late-or-own-move":
            verdict.ties.append((entry["actor"], int(rows[0]), int(rows[-1]) + 1, frame))
        verdict.lines.append(line)
        verdict.diagnosed(diagnosis)

    def _errors(self, vertices, frame: int):
        """Error ``(m, T)`` and allowance ``(m,)`` of vertices ``(T, m, 3)`` held by ``frame``."""
        pos, rot = self._with_world
        index = frame if frame >= 0 else pos.shape[1] - 1
        error = attach_mod._errors(attach_mod.in_frame(vertices, pos[:, index], rot[:, index]))
        return error, attach_mod._allowance(vertices, pos, rot, np.full(vertices.shape[1], index), self.tolerance)

    def drawn(self) -> Verdict:
        if not self._attached_done:
            self.attached()
        verdict = Verdict("drawn", True)
        self.undrawn.clear()
        followed = set(self.followed_badly)  # loose vertices that follow a frame are the attached check's
        for a in self.attachments:
            followed.update(int(f) for f in np.unique(a.frame[a.held]) if f >= 0)
        soft_bodies.drawn(self, verdict, followed)
        for index, frame in enumerate(self.r.frames):
            if frame.node >= 0 or not _shown(frame):  # a soft body's nodes: judged above, the body at once
                continue
            if len(self.welds) and self.welds[index] >= 0:
                # A welded frame is given the vertices on its shape that its weld holds, its neighbours' as well
                # (a link's box whose end lies in the next link's cylinder): drawn means its shape is covered.
                if self._drawn_on_its_weld(index, followed):
                    continue
            elif index in followed:
                continue
            moved = self._movement(index, bounding_radius(frame.shapes))
            allowance = 10 * self.tolerance.for_extents(np.array([bounding_radius(frame.shapes)]),
                                                        self.pos[:1, index])[0] if self.r.ticks else 0
            if moved <= allowance:
                continue
            verdict.passed = False
            self.undrawn.add(index)
            line = (f"{frame.label} moves ({moved:.3g} m over ticks 1..{self.r.ticks}) but no drawn vertex follows it")
            near, rows = self._left_behind(index)
            verdict.lines.append(line + (f"; {near} stays where it was built" if near else ""))
            if near:
                verdict.diagnosed("never-moved")
                if rows is not None:
                    self.left_behind.setdefault(rows[0], set()).update(range(rows[1], rows[2]))
        self._drawn_verdict = verdict
        return verdict

    def _drawn_on_its_weld(self, index: int, followed: set) -> bool:
        """Whether a welded frame is drawn: the vertices its weld holds (whichever member they were given to)
        that lie on its own shapes reach across one of them, in its own frame. An IMU link's millimetre box
        drawn at its origin inside the trunk it is welded to (Unitree A1), a foot's sphere at the end of the
        calf: the vertices go to the parent, and the link is drawn. The end of a link's box lying in the
        next link's cylinder (TwoJointRobot_w_fixedJoints) does not draw that cylinder. A frame whose shapes
        the kit cannot size (no box, sphere or cylinder, no readable visual) is drawn when any is given to it."""
        group = self.welds[index] if len(self.welds) else -1
        if group < 0:
            return False
        members = np.flatnonzero(self.welds == group)
        if not followed.intersection(int(m) for m in members):
            return False
        info = self.r.frames[index]
        shapes = candidates(info.shapes, info.mesh, info.visuals)
        if not shapes:
            return index in followed
        for track, a in zip(self.r.actors, self.attachments):
            rows = np.flatnonzero(np.isin(a.frame, members) & a.held)
            if not len(rows):
                continue
            radii = track.radii[rows] if track.radii is not None else None
            local = _drawn_points(self._reference(track.vertices[1:, rows], index), radii, np.arange(len(rows)))
            on = local[self._outside(index, local) <= self.tolerance.bounds_rtol * bounding_sphere(info.shapes, info.mesh)[1]
                       + 1e-9]
            if not len(on):
                continue
            low, high = on.min(axis=0), on.max(axis=0)
            for _what, _which, centre, half in shapes:
                room = self.tolerance.bounds_rtol * 2 * float(np.max(half)) + 1e-9
                if np.all(low <= centre - half + room) and np.all(high >= centre + half - room):
                    return True  # the vertices on its shapes reach across one of them
        return False

    def _movement(self, index: int, radius: float) -> float:
        if self.r.ticks == 0:
            return 0.0
        p = self.r.positions[:, index]
        turn = (Rotation.from_quat(self.r.orientations[:, index]) * Rotation.from_quat(self.r.orientations[0, index]).inv()).magnitude()
        return float(max(np.max(np.linalg.norm(p - p[0], axis=1)), np.max(turn) * radius))

    def _left_behind(self, index: int) -> tuple[str, tuple | None]:
        """An actor range held by the world that sits on this frame as it was at the start: of several near
        it, one that is the frame's shape there (its extents in the frame's axes), else the nearest (a nail
        drawn beside the rope's last bead is not that bead). Its label, and ``(actor index, start, stop)``
        when it is the frame's shape (else None): those vertices are this frame's drawing, not the world's."""
        found = self._left_behind_all(index)
        if not found:
            return "", None
        ok, _, label, rows = min(found, key=lambda f: (not f[0], f[1]))
        return label, rows if ok else None

    def _left_behind_all(self, index: int) -> list[tuple[bool, float, str]]:
        """``(is the frame's shape, distance, label)`` of each actor range the world (or a body that never
        moves) holds near where this frame was at the start (:meth:`_left_behind`)."""
        info = self.r.frames[index]
        radius = bounding_radius(info.shapes) if info.shapes else bounding_sphere(info.shapes, info.mesh)[1]
        # A frame that never moves holds what the world holds (a static ground plate): either may be named.
        still = [i for i, f in enumerate(self.r.frames) if self._movement(i, bounding_radius(f.shapes) if f.shapes else 0.0) == 0.0]
        origin, turn = self.r.positions[0, index], attach_mod.rotations(self.r.orientations[0, index])
        found = []
        for k, (track, a) in enumerate(zip(self.r.actors, self.attachments)):
            world = np.flatnonzero(((a.frame < 0) | np.isin(a.frame, still)) & a.held)
            if not len(world):
                continue
            # Runs of one holder, and runs across holders: whatever never moves holds them alike, so a link left
            # where it was built whose vertices the world and the ground plate hold in turns (a cylinder's top cap
            # and its bottom one) is one run; a ground drawn next to it in one shared actor is not part of it.
            mask = np.isin(np.arange(len(a.frame)), world)
            runs = dict.fromkeys([*attach_mod.runs(mask, a.frame), *attach_mod.runs(mask, np.zeros(len(a.frame), dtype=int))])
            for start, stop in runs:
                points = track.vertices[0, start:stop]
                distance = float(np.linalg.norm(points.mean(axis=0) - origin))
                if distance <= radius + 0.01:
                    local = (points - origin) @ turn  # in the frame as it was at the start
                    placed = self._place(local, index)
                    if placed.judged and placed.ok:
                        found.append((True, distance, f"{track.label} vertices {start}:{stop}", (k, start, stop)))
                        continue
                # Built in the link frame and never posed: the world holds the frame's shape at its origin (a body
                # that starts near the origin, a brick dropped from 3 cm, is near both); an actor per visual shape,
                # built in the shape's own frame and posed by link @ visual, holds it there without its visual frame.
                unposed = self._place(points, index)
                if unposed.judged and (unposed.ok or unposed.diagnosis == "visual-frame"):
                    found.append((True, distance, f"{track.label} vertices {start}:{stop} (at the world's origin, "
                                  "never posed)", (k, start, stop)))
                elif distance <= radius + 0.01:
                    found.append((False, distance, f"{track.label} vertices {start}:{stop}", (k, start, stop)))
        return found

    @functools.cached_property
    def still(self) -> set[int]:
        """The frames whose pose never changes in the run (a fixed base, a static ground): whatever never moves lies
        in all of them alike, so the part of a drawing each holds is no evidence of what it draws."""
        return {i for i in range(len(self.r.frames)) if self._movement(i, 1.0) == 0.0}

    def drawn_wrong(self) -> set[int]:
        """The frames some check of the vertices found drawn wrong (`attached`, `drawn`, `placed`), and the frames
        welded to them: one rigid drawing, whose picture is not evidence of another shape drawn."""
        found = self.followed_badly | self.misplaced | self.undrawn
        groups = {int(self.welds[f]) for f in found if 0 <= f < len(self.welds) and self.welds[f] >= 0}
        return found | {i for i, g in enumerate(self.welds) if int(g) in groups}

    def placements(self) -> list:
        """``(track, attachment, frame, rows, Placement)`` of every actor's held vertices of every frame,
        computed once: ``placed`` judges them, and ``pictured`` judges the frames they decide are drawn as
        their collision shape."""
        if self._placements is None:
            self._placements = []
            for track, a in zip(self.r.actors, self.attachments):
                for frame in np.unique(a.frame):
                    if frame < 0:
                        continue
                    rows = np.flatnonzero((a.frame == frame) & a.held)
                    if not len(rows):
                        continue
                    result = self._place(_drawn_points(a.reference[rows], track.radii, rows), int(frame))
                    self._placements.append((track, a, int(frame), rows, result))
        return self._placements

    def pictured(self) -> Verdict:
        from conformance.apps import pictured

        return pictured.check(self)

    def placed(self) -> Verdict:
        self.placed_done = True
        self.misplaced.clear()
        verdict = Verdict("placed", True)
        soft: dict[tuple, list] = {}
        # A frame some drawing shows at its size may carry others (a halo, a marker): those are decorations.
        # One drawn only at another size, every part scaled by one factor, is drawn at the wrong size.
        at_its_size = {frame for _, _, frame, _, result in self.placements() if result.judged}
        if self._drawn_verdict is None:
            self.drawn()  # which still vertices are a moving link left where it was built (self.left_behind)
        index = {id(track): k for k, track in enumerate(self.r.actors)}
        for track, a, frame, rows, result in self.placements():
            info = self.r.frames[frame]
            left = self.left_behind.get(index[id(track)], set())
            if left and left.intersection(rows.tolist()):
                rows = np.array([r for r in rows if r not in left], dtype=int)
                if not len(rows):
                    continue  # `drawn` names them: the link left where it was built, not a drawing of this frame
                result = self._place(_drawn_points(a.reference[rows], track.radii, rows), frame)
            if info.node >= 0:
                soft.setdefault((track.label, info.client, info.body, info.name), []).append(
                    (rows, frame, soft_bodies.off_node(self, a.reference[rows], frame)))
                continue
            where = f"{track.label} vertices {vertex_ranges(rows)} held by {info.label}"
            # A welded frame holds what lies on its shape of its weld's drawings, a part, not a drawing of its own.
            if not result.judged and result.scale and frame not in at_its_size and self.welds[frame] < 0:
                verdict.passed = False
                verdict.lines.append(f"{where}: {result.why.removeprefix('not judged: ')}, and nothing draws it at its size")
                # A frame that never moves holds whatever never moves: beside a link left where it was built (`drawn`
                # names it), what it holds may be parts of that link's drawing, not its own drawn at another size.
                left_here = "never-moved" in self._drawn_verdict.diagnoses and frame in self.still
                verdict.diagnosed("" if left_here else "scaled")
                self.misplaced.add(frame)
            elif not result.judged:
                verdict.notes.append(f"{where}: {result.why}")
            elif not result.ok:
                verdict.passed = False
                diagnosis = result.diagnosis or self._other_body(result.offset, frame)
                if diagnosis == "other-body" and not self._on_another_frame(track, rows, frame):
                    diagnosis = ""  # far from its shape, and on no other: a mistake the catalogue does not tell
                if diagnosis in TURNED_IN_ITS_FRAME and self._turned_alike(track, rows, frame):
                    diagnosis = ""  # a rotation mistake of the pose draws it so as well: either could be meant
                verdict.lines.append(f"{where}: {result.why}")
                verdict.diagnosed(diagnosis)
                self.misplaced.add(frame)
        soft_bodies.placed(self, soft, verdict)
        return verdict

    def _turned_alike(self, track, rows, frame: int) -> bool:
        """Whether a rotation mistake of the pose (:data:`~conformance.apps.attachment.TURNS`) puts the drawing of
        ``rows``, held by ``frame``, on the frame's shapes at its first, middle and last tick. On a link whose
        orientation the run never changes (a gripper's base, a fixed robot's mount) a quaternion reordered turns
        the drawing by one constant turn, which is what a shape turned in its frame, or drawn without its visual
        frame, draws: the two cannot be told apart there."""
        ticks = np.unique(np.linspace(0, len(self.pos) - 1, 3).astype(int))
        vertices = track.vertices[1:, rows][ticks]
        for name, (positions, rotations) in zip(attach_mod.VARIANTS, self._variants):
            if name not in attach_mod.TURNS:
                continue
            local = attach_mod.local_coordinates(vertices, positions[ticks, frame, None], rotations[ticks, frame, None])
            if all(result.judged and result.ok
                   for result in (self._place(_drawn_points(points, track.radii, rows), frame) for points in local)):
                return True
        return False

    def _place(self, points: np.ndarray, frame: int):
        """:func:`~conformance.apps.placement.place` of link-frame ``points`` against ``frame``'s shapes."""
        info = self.r.frames[frame]
        return place(points, info.shapes, np.asarray(info.inertial, dtype=np.float64), tolerance=self.tolerance,
                     mesh=info.mesh, visuals=info.visuals, inertial_turn=info.inertial_turn)

    def normals(self) -> Verdict:
        verdict = Verdict("normals", True)
        worst = 0.0
        # A soft body's node has a position and no turn: the normals of a surface that follows nodes turn
        # with its shape, which a right program recomputes every tick; they are judged against that shape.
        soft = np.array([f.node >= 0 for f in self.r.frames] + [False])  # the last entry: the world (-1)
        offsets = np.concatenate([[0], np.cumsum([len(t.vertices[0]) for t in self.r.actors])]).astype(int).tolist()
        for index, (track, a, bad) in enumerate(zip(self.r.actors, self.attachments, self.unfinite)):
            if track.normals is None:
                continue
            if track.radii is not None:  # a shader lights impostor spheres as spheres: no stored normal is used
                verdict.notes.append(f"{track.label}: spheres drawn by a shader (impostors), lit as spheres whatever "
                                     "their stored normals: not judged")
                continue
            frames = a.frame
            rot = np.concatenate([self.rot, np.broadcast_to(np.eye(3), self.rot.shape[:1] + (1, 3, 3))], axis=1)
            local = np.einsum("tnji,tnj->tni", rot[:, frames], track.normals[1:])
            reference = np.median(local, axis=0)
            reference /= np.maximum(np.linalg.norm(reference, axis=1, keepdims=True), 1e-12)
            angle = np.arccos(np.clip(np.einsum("tni,ni->tn", local, reference), -1, 1))
            # Vertices no frame holds fail `attached`; their normals have no frame to turn with.
            on_nodes = soft[frames] & a.held
            judged = a.held & ~on_nodes & ~bad & np.isfinite(angle).all(axis=0)
            if on_nodes.any():
                worst = max(worst, self._surface_normals(verdict, index, track, a, on_nodes & ~bad, offsets))
            worst = max(worst, float(angle[:, judged].max(initial=0)) / self.tolerance.normal_angle)
            bad = np.any(angle > self.tolerance.normal_angle, axis=0) & judged
            for start, stop in attach_mod.runs(bad, frames):
                verdict.passed = False
                first = int(np.flatnonzero(np.any(angle[:, start:stop] > self.tolerance.normal_angle, axis=1))[0])
                verdict.lines.append(f"{track.label} normals {start}:{stop}: do not turn with {self.frame_label(int(frames[start]))} "
                                     f"from tick {first + 1} ({np.degrees(angle[:, start:stop].max()):.3g}° off; allowed "
                                     f"{np.degrees(self.tolerance.normal_angle):.3g}°)")
                verdict.diagnosed("stale-normals")
        verdict.worst = worst
        return verdict

    def _surface_normals(self, verdict: Verdict, index: int, track, a, on_nodes: np.ndarray, offsets: list) -> float:
        """Judge the stored normals of ``track``'s vertices that follow soft-body nodes (``on_nodes``) against the
        drawn surface (:mod:`conformance.apps.surface_normals`); the worst, in units of its angle."""
        faces = surface_normals.triangles(self.r.pictures, offsets, index, len(on_nodes))
        if faces is None or not len(faces):
            verdict.notes.append(f"{track.label}: {int(on_nodes.sum())} vertices follow soft-body nodes, whose normals turn "
                                 "with the surface's shape: not judged (no picture kept the faces that shape is made of)")
            return 0.0
        # vertices on one node are one point of the surface (a mesh drawn with its corners unshared)
        points = np.where(on_nodes, a.frame, -2 - np.arange(len(on_nodes)))
        # a few ticks at a time: a cloth of 10,000 nodes has 20,000 faces a tick to turn into normals
        chunk = max(1, 2_000_000 // max(len(faces), 1))
        off = np.concatenate([surface_normals.beyond(track.vertices[1 + t:1 + t + chunk], track.normals[1 + t:1 + t + chunk],
                                                     faces, points) for t in range(0, self.r.ticks, chunk)])
        off = np.where(on_nodes & np.isfinite(off).all(axis=0), off, -np.inf)
        outside = off > surface_normals.ANGLE
        if outside.any():
            verdict.passed = False
            ticks, vertices = np.flatnonzero(outside.any(axis=1)), np.flatnonzero(outside.any(axis=0))
            tick, vertex = np.unravel_index(int(np.argmax(off)), off.shape)
            bodies = sorted({self.r.frames[f].label.replace(f" node {self.r.frames[f].node}", "") for f in a.frame[vertices].tolist()})
            verdict.lines.append(
                f"{track.label} normals: {len(vertices)} of {int(on_nodes.sum())} vertices that follow "
                f"{', '.join(bodies)} are not the normals of the surface drawn, from tick {int(ticks[0]) + 1} on "
                f"{len(ticks)} of {off.shape[0]} ticks; the most, vertex {vertex} at tick {tick + 1}: "
                f"{np.degrees(off[tick, vertex]):.3g}° outside the faces that meet there (allowed "
                f"{np.degrees(surface_normals.ANGLE):.3g}°)")
            verdict.diagnosed("surface-normals")
        else:
            verdict.notes.append(f"{track.label}: {int(on_nodes.sum())} vertices follow soft-body nodes: their normals are "
                                 f"those of the surface drawn (at most {np.degrees(max(float(off.max(initial=0.0)), 0.0)):.2g}° "
                                 f"outside the faces that meet there; allowed {np.degrees(surface_normals.ANGLE):.3g}°)")
        return float(np.max(off, initial=0.0)) / surface_normals.ANGLE

    def announced(self) -> Verdict:
        verdict = Verdict("announced", True)
        for track in self.r.actors:
            # A change with nothing announced, or (FURY 2, buffer by buffer) outside what was announced.
            silent = sorted(set((np.flatnonzero(track.changed[1:] & ~track.announced[1:]) + 1).tolist())
                            | {tick for tick, _ in track.missed})
            if silent:
                verdict.passed = False
                words = dict(track.missed).get(silent[0])
                what = (f"at tick {silent[0]} {words}" if words else
                        f"its vertex data changed at tick {silent[0]} without being announced to the renderer")
                verdict.lines.append(f"{track.label} ({track.kind}): {what} ({len(silent)} ticks in all)")
                # Announced, but not where it changed (FURY 2's ranges, conformance.backends.pygfx.unannounced's
                # words): the GPU keeps the rest, which is what stale-gpu says; nothing announced is unannounced
                verdict.diagnosed("stale-gpu" if words and "outside every range announced" in words else "unannounced")
        return verdict


    def _writers(self, tick: int) -> set:
        return set(self.r.writers[tick]) if tick < len(self.r.writers) else set()

    def untouched(self) -> Verdict:
        """A write after the tick's last step is the app's business when it moves a body on purpose (kinematic
        playback by ``resetJointState``, a body teleported or pushed before the draw): the drawing is then judged
        against what pyBullet holds when it draws, as every drawing is. What a sync must never do is write its
        own drawing back ("so physics and graphics agree"): a pose reset to what it already was, to float32
        rounding or exactly, which still changes the simulation (the velocity is set to zero, the last bits of
        the pose are lost). The two are told apart body by body and tick by tick by what the write changed: a
        body whose frames all moved no further than float32 rounding of their pose (with a pose writer called)
        was written back; a body some frame of which moved further was moved on purpose."""
        verdict = Verdict("untouched", True)
        writes = self.r.writes
        if writes is None or not np.isfinite(writes).any():
            return verdict
        before, after = writes[..., :13], writes[..., 13:]
        moved = np.linalg.norm(after[..., :3] - before[..., :3], axis=-1)
        turned = np.full(moved.shape, np.nan)
        known = np.isfinite(before[..., 3:7]).all(axis=-1) & np.isfinite(after[..., 3:7]).all(axis=-1)
        turned[known] = (Rotation.from_quat(after[..., 3:7][known]) * Rotation.from_quat(before[..., 3:7][known]).inv()).magnitude()
        sped = np.linalg.norm(after[..., 7:] - before[..., 7:], axis=-1)
        change = np.nan_to_num(np.maximum(np.maximum(moved, turned), sped), nan=0.0)
        changed = change > UNTOUCHED_ATOL
        if not changed.any():
            return verdict
        # Within float32 rounding (with a float32 normalisation) of the pose it had: the drawn pose written back.
        eps = 4 * np.finfo(np.float32).eps
        rounded = np.all(np.abs(after[..., :7] - before[..., :7]) <= eps * np.maximum(np.abs(before[..., :7]), 1.0), axis=-1)
        bodies: dict[tuple, list[int]] = {}
        for index, frame in enumerate(self.r.frames):
            bodies.setdefault((frame.client, frame.body), []).append(index)
        back = np.zeros_like(changed)   # (tick, frame): part of a body written back at that tick
        on_purpose: dict[tuple, set] = {}
        for tick in np.flatnonzero(changed.any(axis=1)):
            writers = self._writers(tick)
            for key, rows in bodies.items():
                if not changed[tick, rows].any():
                    continue
                if writers & POSE_WRITERS and np.all(rounded[tick, rows]):
                    back[tick, rows] = changed[tick, rows]
                else:
                    on_purpose.setdefault(key, set()).add(int(tick))
        if on_purpose:
            calls = ", ".join(sorted({name for ticks in on_purpose.values() for t in ticks for name in self._writers(t)}))
            ticks = sorted(set().union(*on_purpose.values()))
            verdict.notes.append(
                f"the app moves {len(on_purpose)} bod{'y' if len(on_purpose) == 1 else 'ies'} on purpose after its last "
                f"p.stepSimulation() ({calls}) on {len(ticks)} of {self.r.ticks} ticks, first at tick {ticks[0]}: what it "
                "draws is judged against what pyBullet holds when it draws (attached)")
        if not back.any():
            return verdict
        verdict.passed = False
        ticks = np.flatnonzero(back.any(axis=1))
        frames = np.flatnonzero(back.any(axis=0))
        tick, frame = np.unravel_index(int(np.argmax(np.where(back, change, -1))), change.shape)
        first = int(ticks[0])
        calls = ", ".join(sorted({name for t in ticks for name in self._writers(t)} & POSE_WRITERS))
        verdict.lines.append(
            f"after the last p.stepSimulation() of tick {first}, the app's own code wrote back what pyBullet computed "
            f"({calls}): {len(frames)} frame(s) on {len(ticks)} of {self.r.ticks} ticks set to their own pose, to float32 "
            f"rounding or exactly; the most, {self.frame_label(int(frame))} at tick {tick}: moved {moved[tick, frame]:.3g} m, "
            f"turned {turned[tick, frame]:.3g} rad, velocity changed by {np.nan_to_num(sped[tick, frame]):.3g} (m/s, rad/s); "
            f"allowed {UNTOUCHED_ATOL:g} (a sync only reads the simulation)")
        verdict.diagnosed("written-back")
        verdict.worst = float(change[back].max())
        return verdict


def _attach_finite(vertices: np.ndarray, bad: np.ndarray, *args, **kwargs):
    """:func:`conformance.apps.attachment.attach` of the finite vertices of ``vertices`` ``(T, n, 3)``; the ``bad``
    ones (not finite at some tick, ``attached`` fails them) given to the world and taken as held, so that no
    other check reads them."""
    if not bad.any():
        return attach_mod.attach(vertices, *args, **kwargs)
    ticks, n = vertices.shape[:2]
    found = attach_mod.Attachment(frame=np.full(n, -1), error=np.zeros((n, ticks)), allowance=np.ones(n),
                                  reference=np.zeros((n, 3)), tied=np.zeros(n, dtype=bool), welded=np.zeros(n, dtype=bool))
    if (~bad).any():
        good = attach_mod.attach(vertices[:, ~bad], *args, **kwargs)
        found.frame[~bad], found.error[~bad], found.allowance[~bad] = good.frame, good.error, good.allowance
        found.reference[~bad], found.tied[~bad] = good.reference, good.tied
        if good.welded is not None:
            found.welded[~bad] = good.welded
    return found


def _shown(frame) -> bool:
    """Whether pyBullet's own renderer draws ``frame``, so a right program must: some visual shape of it has an
    extent and is not invisible (alpha 0). A URDF says "a frame, no picture" with a zero-radius sphere, a
    program hides a link with ``changeVisualShape(rgbaColor=(…, 0))``, an MJCF joint holder has no shape at
    all: none of these is drawn (measured, pybullet 3.2.7: 0 or 1 pixel of its segmentation mask, against
    225 for the same box visible). A recording made before the kit counted visual shapes judges by the
    collision shape, as it did."""
    return frame.shown > 0 if frame.shown >= 0 else bool(frame.shapes)


def _drawn_points(reference: np.ndarray, radii: np.ndarray | None, rows: np.ndarray) -> np.ndarray:
    """What a drawing covers, in its frame: its vertices; for an impostor sphere (a vertex at its centre,
    :attr:`~conformance.apps.recording.ActorTrack.radii`) the six points of its sphere on the frame's axes,
    so that it spans the box of the sphere it draws."""
    if radii is None:
        return reference
    r = radii[rows][:, None, None]
    axes = np.concatenate([np.eye(3), -np.eye(3)])[None]
    return (reference[:, None, :] + r * axes).reshape(-1, 3)


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
