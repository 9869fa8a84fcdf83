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

Everything is computed from the :class:`~conformance.apps.recording.Recording` alone.
"""

from __future__ import annotations

import functools

import numpy as np
from scipy.spatial.transform import Rotation

from conformance.apps import attachment as attach_mod, soft_bodies, surface_normals, welds
from conformance.apps.verdict import DIAGNOSES, Verdict
from conformance.apps.placement import bounding_radius, bounding_sphere, candidates, place, shape_distance
from conformance.apps.recording import Recording, vertex_ranges
from conformance.judge.tolerances import DEFAULT, Tolerance

__all__ = ["CHECKS", "DIAGNOSES", "Verdict", "judge"]

CHECKS = ("runs", "attached", "drawn", "placed", "normals", "announced", "untouched", "pictured")

#: A write that changes a pose or velocity by no more than this is no change (resetting a body to the
#: pose just read may round its last bit).
UNTOUCHED_ATOL = 1e-12
#: pyBullet's calls that set a pose (a write-back writes one): the driver's STATE_WRITERS but resetBaseVelocity
POSE_WRITERS = {"resetBasePositionAndOrientation", "resetJointState", "resetJointStateMultiDof", "resetJointStatesMultiDof"}
#: :meth:`_Judgement._owners`' mistake index of the pose before the app's own moves: one past the catalogue
_OWN_MOVE = len(attach_mod.VARIANTS) + 1
#: Of two rotation mistakes that hold a drawing alike, the one made is the one under which the drawing lies on its
#: frame's shapes (its vertices on average within this share of its reach of them) while under every other it
#: lies off them (past the second share): the other puts the shape flipped, a link's length off its origin
#: (cartpole's pole, 0.5 m; half_cheetah's thighs). A visual mesh is judged by shapes that only approximate it,
#: so between the two nothing is named.
ON_ITS_SHAPE, OFF_ITS_SHAPE = 0.05, 0.25
#: A drawing lies on a frame's shapes when its vertices are within this share of its own reach of them, on
#: average (:meth:`_Judgement._on_another_frame`)
ON_SHAPE = 0.25


def _rotations(q: np.ndarray) -> np.ndarray:
    return Rotation.from_quat(q.reshape(-1, 4)).as_matrix().reshape(q.shape[:-1] + (3, 3))


class _Judgement:
    def __init__(self, recording: Recording, tolerance: Tolerance):
        self.r, self.tolerance = recording, tolerance
        self.pos = recording.positions[1:]
        self.orn = recording.orientations[1:]
        self.rot = _rotations(self.orn) if self.orn.size else np.zeros(self.orn.shape[:-1] + (3, 3))
        self.event_ticks = sorted({int(e["frame"]) - 1 for e in recording.events})
        self._distances: dict = {}  # frame -> its shape_distance, hulls computed once
        spheres = [bounding_sphere(f.shapes, f.mesh) for f in recording.frames]
        centres = np.array([c for c, _ in spheres]).reshape(-1, 3)
        radii = np.array([r for _, r in spheres])
        #: frames welded together (fixed joints): one rigid frame, whose vertices go to the member they lie on
        self.welds = welds.groups(recording.frames, recording.positions, _rotations(recording.orientations)) \
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
    def _variants(self) -> list[tuple[np.ndarray, np.ndarray]]:
        """Every frame's positions ``(T, F, 3)`` and rotations ``(T, F, 3, 3)`` under each mistake of the
        catalogue (:data:`~conformance.apps.attachment.VARIANTS`, in its order): computed once for all frames,
        not once for each loose piece and frame (a wrong 100-brick wall's diagnosis spent most of its time there)."""
        before_pos, before_orn = self.r.before_positions[1:], self.r.before_orientations[1:]
        made = [tuple(np.asarray(a) for a in make(self.pos, self.orn, before_pos, before_orn))
                for _, make in attach_mod.VARIANTS.values()]
        # The one mistake whose pose depends on each frame's shapes, not on its pose alone
        made[list(attach_mod.VARIANTS).index("visual-frame, order")] = attach_mod.visual_order(
            self.pos, self.rot, self.r.frames)
        made[list(attach_mod.VARIANTS).index("previous-step, tick")] = (
            self.r.positions[:-1], _rotations(self.r.orientations[:-1]))
        return made

    @functools.cached_property
    def _variant_stack(self) -> tuple[np.ndarray, np.ndarray]:
        """:attr:`_variants` stacked: positions ``(V, T, F, 3)`` and rotations ``(V, T, F, 3, 3)``."""
        shape = self.pos.shape
        return (np.stack([np.broadcast_to(p, shape) for p, _ in self._variants]),
                np.stack([np.broadcast_to(r, shape + (3,)) for _, r in self._variants]))

    def _variants_possible(self, vertices, frame, reference, allowance, bad_ticks) -> np.ndarray:
        """``(V,)``: whether each variant could hold the vertices, judged by the first one alone under every
        variant at once (the test :func:`~conformance.apps.attachment.variant_fit` makes, with a hair of
        slack): a loose piece's diagnosis tried the catalogue variant by variant, most of judging a robot
        drawn with degrees for radians."""
        if not vertices.shape[1] or not len(bad_ticks):
            return np.ones(len(self._variants), dtype=bool)
        pos, rot = self._variant_stack
        local = np.einsum("vtji,vtj->vti", rot[:, :, frame], vertices[None, :, 0] - pos[:, :, frame])
        limit = allowance[0] * (1 + 1e-9)
        at_reference = np.all(np.linalg.norm(local[:, bad_ticks] - reference[0], axis=-1) <= limit, axis=1)
        own = np.median(local, axis=1)
        at_own = np.all(np.linalg.norm(local[:, bad_ticks] - own[:, None], axis=-1) <= limit, axis=1)
        return at_reference | at_own

    @functools.cached_property
    def _radii(self) -> np.ndarray:
        """How far each frame's collision shapes reach from its origin (0 for a frame without)."""
        return np.array([bounding_radius(f.shapes) if f.shapes else 0.0 for f in self.r.frames])

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
                bad_ticks = _bad_ticks(error, allowance)
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
            for start, stop in _runs(bad, np.zeros(len(bad), dtype=int)):
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
        bad_ticks = _bad_ticks(error, allowance)
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

    def _loose_pieces(self, track, a, loose):
        """``(start, stop, frame, diagnosis)`` of the actor's loose vertices, one per body or link they were
        meant to follow (one shared actor draws many): each vertex goes to the nearby frame that holds it
        under a known mistake (or, when none does, that it follows best), and consecutive vertices with the
        same frame and mistake make one piece."""
        pieces = []
        late = list(attach_mod.VARIANTS).index("previous-step") + 1

        def add(piece, frame, diagnosis):
            if pieces and pieces[-1][1] == piece[0] and pieces[-1][2:] == (frame, diagnosis):
                pieces[-1] = (pieces[-1][0], int(piece[-1]) + 1, frame, diagnosis)
            else:
                pieces.append((int(piece[0]), int(piece[-1]) + 1, frame, diagnosis))

        for start, stop in _runs(loose, np.zeros(len(loose), dtype=int)):
            rows = np.arange(start, stop)
            frames, mistakes = self._owners(track.vertices[1:, rows], a.frame[rows], a.allowance[rows])
            # Where a joint reset barely moved a link, the poses before the step and before the app's own
            # moves both hold its vertices, and each vertex went to the nearer by a hair: a mini cheetah's thigh
            # in 377 runs of the two. Told on the whole run; where that names nothing, run by run as found.
            merged = np.where(mistakes == late, _OWN_MOVE, mistakes)
            for s, e in _runs(np.ones(len(rows), dtype=bool), frames * (_OWN_MOVE + 1) + merged):
                piece, frame = rows[s:e], int(frames[s])
                if set(mistakes[s:e].tolist()) == {late, _OWN_MOVE}:
                    diagnosis = self._own_move_of(track, a, piece, frame)
                    if diagnosis:
                        add(piece, frame, diagnosis)
                        continue
                for s2, e2 in _runs(np.ones(e - s, dtype=bool), mistakes[s:e]):
                    add(piece[s2:e2], *self._piece(track, a, piece[s2:e2], frame, int(mistakes[s + s2])))
        return pieces

    def _own_move_of(self, track, a, piece, frame: int) -> str:
        """:meth:`_later_than_the_step` of a piece :meth:`_owners` gave to ``frame``, which may not be the one the
        attachment found for it: the reference is where the drawing sits in that one, of no use in another."""
        reference = a.reference[piece] if np.all(a.frame[piece] == frame) else None
        return self._later_than_the_step(track.vertices[1:, piece], frame, reference)

    def _piece(self, track, a, piece, frame: int, mistake: int) -> tuple[int, str]:
        """The frame and diagnosis of a run of loose vertices that :meth:`_owners` gave to ``frame`` under
        ``mistake`` (0 none, :data:`_OWN_MOVE` the pose before the app's own moves)."""
        vertices = track.vertices[1:, piece]
        if mistake == _OWN_MOVE:
            diagnosis = self._own_move_of(track, a, piece, frame)
            return (frame, diagnosis) if diagnosis else self._followed(vertices, a.frame[piece], a.reference[piece])
        if mistake:
            diagnosis = list(attach_mod.VARIANTS)[mistake - 1]
            if diagnosis in attach_mod.TURNS:  # the first that holds it; a later one may hold it alike
                return frame, self._turn_on_its_shape(frame, self._turns_holding(vertices, frame, diagnosis))
            diagnosis = attach_mod.ALIASES.get(diagnosis, diagnosis)
            if diagnosis == "previous-step":  # or later than the step: before the app's own moves
                diagnosis = self._later_than_the_step(vertices, frame, a.reference[piece]) or diagnosis
            return frame, diagnosis
        return self._followed(vertices, a.frame[piece], a.reference[piece])

    def _owners(self, vertices, best, allowance) -> tuple[np.ndarray, np.ndarray]:
        """Per loose vertex ``(T, m, 3)``: the frame index it belongs to and the mistake (1-based index into
        the catalogue, 0 none, one past the catalogue the pose before the app's own moves) under which that
        frame holds it. Candidates are the frames near it at tick 1 (within twice their shape's radius) and
        the frame that came nearest to holding it."""
        m = vertices.shape[1]
        frames = np.where(best >= 0, best, 0).astype(int)
        mistakes = np.zeros(m, dtype=int)
        if not self.r.frames:
            return frames, mistakes
        radius = self._radii
        distance = np.linalg.norm(vertices[0][:, None, :] - self.pos[0][None, :, :], axis=-1)  # (m, F)
        near = distance <= 2 * radius[None, :] + 1e-9
        near[np.arange(m)[best >= 0], best[best >= 0]] = True
        score = np.full(m, np.inf)
        ticks = len(vertices)
        probes = np.unique(np.linspace(0, ticks - 1, 4).astype(int)) if ticks else np.arange(0)
        # A drawing at the pose before the app's own moves (a playback drawn before its resetJointState) is
        # found here in runs of its frames; left to _followed, it fell apart into thousands of pieces, each
        # diagnosed on its own (36 s of a Franka playback's judgement). A robot's visual meshes reach past its
        # collision shapes and its link origins crowd at the joints, so no nearness finds a vertex's frame:
        # under this pose every frame the app moved is a candidate (a probe of 4 ticks rules most out).
        before = self._poses_before_writes
        near_own = np.zeros_like(near)
        if before is not None:
            near_own[:] = before[2].any(axis=0)[None, :]
        for f in np.flatnonzero(near.any(axis=0) | near_own.any(axis=0)):
            poses = list(self._variants) + ([before[:2]] if near_own[:, f].any() else [])
            for k, (positions, rotations) in enumerate(poses, start=1):
                near_f = np.flatnonzero(near_own[:, f] if k == _OWN_MOVE else near[:, f])
                if not len(near_f):
                    continue
                # Held within the allowance of one place at every tick means within twice it of the first
                # tick's place at a few: a necessary test on 4 ticks of 40 rules most pairs out (exact).
                probed = attach_mod.in_frame(vertices[probes][:, near_f], positions[probes, f], rotations[probes, f])
                spread = np.max(np.linalg.norm(probed - probed[:1], axis=-1), axis=0, initial=0)
                rows = near_f[spread <= 2 * allowance[near_f] * (1 + 1e-9)]
                if not len(rows):
                    continue
                local = attach_mod.in_frame(vertices[:, rows], positions[:, f], rotations[:, f])
                error = attach_mod._errors(local).max(axis=1) / allowance[rows]
                better = (error <= 1.0) & (error < score[rows])
                frames[rows[better]], mistakes[rows[better]], score[rows[better]] = f, k, error[better]
        return frames, mistakes

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
            bad_ticks = _bad_ticks(error, allowance)
            diagnosis = self._diagnose(vertices, frame, reference, allowance, bad_ticks)
            if diagnosis:
                return frame, diagnosis
            scored.append((float(np.median(error)), frame))
        world, _ = self._errors(vertices, -1)
        scored.append((float(np.median(world)) + 1e-12, -1))
        return min(scored)[1], ""

    def _errors(self, vertices, frame: int):
        """Error ``(m, T)`` and allowance ``(m,)`` of vertices ``(T, m, 3)`` held by ``frame``."""
        pos, rot = self._with_world
        index = frame if frame >= 0 else pos.shape[1] - 1
        error = attach_mod._errors(attach_mod.in_frame(vertices, pos[:, index], rot[:, index]))
        return error, attach_mod._allowance(vertices, pos, rot, np.full(vertices.shape[1], index), self.tolerance)

    def _diagnose(self, vertices, frame, reference, allowance, bad_ticks) -> str:
        if frame < 0:
            return ""
        own = self._before_own_move(vertices, frame, reference, allowance, bad_ticks)
        if own:
            return own
        possible = self._variants_possible(vertices, frame, reference, allowance, bad_ticks)
        turns = []  # the rotation mistakes that hold the vertices: (name, their own place in that frame)
        for name, (positions, rotations), could in zip(attach_mod.VARIANTS, self._variants, possible):
            if not could or (turns and name not in attach_mod.TURNS):
                continue
            positions, rotations = positions[:, frame, None], rotations[:, frame, None]
            if attach_mod.variant_fit(vertices, positions, rotations, reference, allowance, bad_ticks):
                # A late sync is late wherever the body moved; drawn right at some of those ticks, it skipped
                if name == "previous-step" and not attach_mod.variant_fit(
                        vertices, positions, rotations, reference, allowance, np.arange(len(vertices))):
                    return "skipped"
                if name not in attach_mod.TURNS:
                    return attach_mod.ALIASES.get(name, name)
                turns.append((attach_mod.ALIASES.get(name, name),
                              np.median(attach_mod.local_coordinates(vertices, positions, rotations), axis=0)))
        if turns:
            return self._turn_on_its_shape(frame, turns)
        if self._visual_order_fits(vertices, frame, reference, allowance, bad_ticks):
            return "visual-frame"
        return "skipped" if self._skipped(vertices, frame, allowance) else ""

    def _turns_holding(self, vertices, frame: int, first: str) -> list:
        """``(name, own place)`` of the rotation mistakes from ``first`` on (a key of the catalogue, which holds
        ``vertices``) that hold them in ``frame``, each at one fixed place of its own at every tick."""
        _, allowance = self._errors(vertices, frame)
        ticks = np.arange(len(vertices))
        found = []
        for name, (positions, rotations) in list(zip(attach_mod.VARIANTS, self._variants))[list(attach_mod.VARIANTS).index(first):]:
            if name not in attach_mod.TURNS:
                continue
            positions, rotations = positions[:, frame, None], rotations[:, frame, None]
            if name == first or attach_mod.variant_fit(vertices, positions, rotations, None, allowance, ticks):
                found.append((attach_mod.ALIASES.get(name, name),
                              np.median(attach_mod.local_coordinates(vertices, positions, rotations), axis=0)))
        return found

    def _turn_on_its_shape(self, frame: int, turns: list) -> str:
        """Which of several rotation mistakes that each hold a drawing made it: the one under which the drawing
        lies on its frame's shapes. Two can hold it alike: a link turning about the world's y axis drawn with
        its quaternion reordered (w, x, y, z) is drawn as by the inverse rotation of its shape flipped about its
        x axis, at every tick (R(wxyz of q) = R(q)ᵀ·Rx(π)), so only where the shape lies tells them apart. ""
        when none or several lie on it (a shape the flip leaves as it was): either could be meant."""
        if len(turns) == 1:
            return turns[0][0]
        own = turns[0][1]
        if len(own) < 4:  # a few vertices of a drawing lie on a shape, or off it, whichever way it is turned
            return ""
        reach = max(float(np.max(np.linalg.norm(own - own.mean(axis=0), axis=1))), 1e-9)  # a turn keeps it
        outside = np.array([float(np.mean(self._outside(frame, place))) for _, place in turns]) / reach
        on, off = outside <= ON_ITS_SHAPE, outside > OFF_ITS_SHAPE
        return turns[int(np.argmin(outside))][0] if on.sum() == 1 and off.sum() == len(turns) - 1 else ""

    def _visual_order_fits(self, vertices, frame, reference, allowance, bad_ticks) -> bool:
        """Whether one of the frame's several visual frames, composed the wrong way round with its pose, holds
        the vertices: one actor per visual shape posed by ``visual @ link`` (the catalogue's variant covers a
        frame with one visual frame; a robot's link often has several)."""
        placed = attach_mod.visual_frames(self.r.frames[frame]) if frame < len(self.r.frames) else []
        if len(placed) < 2:
            return False
        for p_v, q_v in placed:
            positions, rotations = attach_mod.visual_order_of(self.pos[:, frame], self.rot[:, frame], p_v, q_v)
            if attach_mod.variant_fit(vertices, positions[:, None], rotations[:, None], reference, allowance, bad_ticks):
                return True
        return False

    @functools.cached_property
    def _poses_before_writes(self) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """Each frame's pose after the tick's last step and before the app's own first write of the tick
        (positions ``(T, F, 3)``, rotations ``(T, F, 3, 3)``), the pose it drew at ticks without a write that
        moved it; and ``(T, F)`` where a write moved it. None when the app moved nothing after its steps."""
        writes = self.r.writes
        if writes is None or not len(self.pos):
            return None
        before = writes[1:len(self.pos) + 1, :, :7]
        known = np.isfinite(before).all(axis=-1)
        held = np.where(known[..., None], before, np.concatenate([self.pos, self.orn], axis=-1))
        # A joint reset may turn a link about its own origin: moved is moved or turned.
        turned = 1 - np.abs(np.sum(held[..., 3:7] * self.orn, axis=-1)) > 1e-12
        moved = known & ((np.linalg.norm(self.pos - held[..., :3], axis=-1) > UNTOUCHED_ATOL) | turned)
        if not moved.any():
            return None
        positions = np.where(moved[..., None], held[..., :3], self.pos)
        rotations = np.where(moved[..., None, None], _rotations(np.where(moved[..., None], held[..., 3:7], self.orn)),
                             self.rot)
        return positions, rotations, moved

    def _before_own_move(self, vertices, frame, reference, allowance, bad_ticks) -> str:
        """``"before-own-move"`` when the vertices sit, at the failing ticks, where the frame was after the step
        and before the app's own moves of that tick (``resetJointState`` of a playback), and not at its pose
        before the step: the sync ran between them. Where both poses hold them (a step that moves a kinematic
        arm less than the allowance: after ``resetJointState`` a step leaves its joints exactly where they
        were, measured) this run cannot tell the two mistakes apart: ``"late-or-own-move"``, which
        :mod:`~conformance.apps.told_apart` settles with a run of its own."""
        before = self._poses_before_writes
        if before is None or not before[2][:, frame].any() or not len(bad_ticks):
            return ""
        positions, rotations, _ = before
        positions, rotations = positions[:, frame, None], rotations[:, frame, None]
        if not attach_mod.variant_fit(vertices, positions, rotations, reference, allowance, bad_ticks):
            return ""
        late = list(attach_mod.VARIANTS).index("previous-step")
        late_pos, late_rot = (a[:, frame, None] for a in self._variants[late])
        if not attach_mod.variant_fit(vertices, late_pos, late_rot, reference, allowance, bad_ticks):
            return "before-own-move"
        own = attach_mod.local_coordinates(vertices[bad_ticks], positions[bad_ticks], rotations[bad_ticks])
        behind = attach_mod.local_coordinates(vertices[bad_ticks], late_pos[bad_ticks], late_rot[bad_ticks])
        apart = float(np.max(np.linalg.norm(own - behind, axis=-1), initial=0.0))
        limit = float(np.max(allowance))
        if apart > limit and reference is not None:
            # Each pose holds the drawing at a place of its own: the drawing's place in the frame says which,
            # where it is one of them. Read from a drawing wrong at every tick it is neither (a median of
            # wrong places), and then this run cannot tell, as when the two places are one.
            own_off, behind_off = (float(np.max(np.linalg.norm(local - reference, axis=-1))) for local in (own, behind))
            if min(own_off, behind_off) <= limit:
                return "before-own-move" if own_off < behind_off else ""
        # A late sync is late wherever the body moved; drawn right at some of those ticks, it skipped
        if not attach_mod.variant_fit(vertices, positions, rotations, reference, allowance, np.arange(len(vertices))):
            return "skipped"
        return "late-or-own-move"

    def _later_than_the_step(self, vertices, frame, reference) -> str:
        """:meth:`_before_own_move` for a piece :meth:`_owners` found a step late or before the app's own moves
        (``reference`` None when the frame is not the one the attachment found for it)."""
        error, allowance = self._errors(vertices, frame)
        bad_ticks = _bad_ticks(error, allowance)
        return self._before_own_move(vertices, frame, reference, allowance, bad_ticks)

    def _skipped(self, vertices, f, allowance) -> bool:
        """Whether at every tick the vertices sit, in their frame, where they sat at one of the first ticks,
        under pyBullet's pose of that tick or of the one before it, and under the one before at some tick:
        a sync that runs every other tick, or skips a body now and then, while the body moves (the median
        reference of half-wrong ticks fits neither pose, so the variants above cannot see it)."""
        ticks = len(vertices)
        if ticks < 3:
            return False
        turns = _rotations(self.r.before_orientations[1:][:, f])
        # Every vertex must sit so at every tick: one that does not at some tick, under every first tick,
        # rules the piece out at the cost of one vertex (most pieces of a wrong drawing).
        if vertices.shape[1]:
            one = vertices[:, :1]
            now, before = (attach_mod.in_frame(one, self.pos[:, f], self.rot[:, f]),
                           attach_mod.in_frame(one, self.r.before_positions[1:][:, f], turns))
            if not any(np.all((np.linalg.norm(now - now[first], axis=-1) <= allowance[:1])
                              | (np.linalg.norm(before - now[first], axis=-1) <= allowance[:1]))
                       for first in range(min(3, ticks))):
                return False
        now = attach_mod.in_frame(vertices, self.pos[:, f], self.rot[:, f])
        before = attach_mod.in_frame(vertices, self.r.before_positions[1:][:, f], turns)
        for first in range(min(3, ticks)):
            right = np.all(np.linalg.norm(now - now[first], axis=-1) <= allowance, axis=1)
            late = np.all(np.linalg.norm(before - now[first], axis=-1) <= allowance, axis=1)
            if np.all(right | late) and np.any(late & ~right) and np.any(right[1:] & ~late[1:]):
                return True
        return False

    def drawn(self) -> Verdict:
        if not self._attached_done:
            self.attached()
        verdict = Verdict("drawn", True)
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
        origin, turn = self.r.positions[0, index], _rotations(self.r.orientations[0, index])
        found = []
        for k, (track, a) in enumerate(zip(self.r.actors, self.attachments)):
            world = np.flatnonzero(((a.frame < 0) | np.isin(a.frame, still)) & a.held)
            if not len(world):
                continue
            # Runs of one holder, and runs across holders: whatever never moves holds them alike, so a link left
            # where it was built whose vertices the world and the ground plate hold in turns (a cylinder's top cap
            # and its bottom one) is one run; a ground drawn next to it in one shared actor is not part of it.
            mask = np.isin(np.arange(len(a.frame)), world)
            runs = dict.fromkeys([*_runs(mask, a.frame), *_runs(mask, np.zeros(len(a.frame), dtype=int))])
            for start, stop in runs:
                points = track.vertices[0, start:stop]
                distance = float(np.linalg.norm(points.mean(axis=0) - origin))
                if distance <= radius + 0.01:
                    local = (points - origin) @ turn  # in the frame as it was at the start
                    placed = place(local, info.shapes, self._inertial(index), tolerance=self.tolerance, mesh=info.mesh,
                                   visuals=info.visuals)
                    if placed.judged and placed.ok:
                        found.append((True, distance, f"{track.label} vertices {start}:{stop}", (k, start, stop)))
                        continue
                # Built in the link frame and never posed: the world holds the frame's shape at its origin (a body
                # that starts near the origin, a brick dropped from 3 cm, is near both); an actor per visual shape,
                # built in the shape's own frame and posed by link @ visual, holds it there without its visual frame.
                unposed = place(points, info.shapes, self._inertial(index), tolerance=self.tolerance,
                                mesh=info.mesh, visuals=info.visuals)
                if unposed.judged and (unposed.ok or unposed.diagnosis == "visual-frame"):
                    found.append((True, distance, f"{track.label} vertices {start}:{stop} (at the world's origin, "
                                  "never posed)", (k, start, stop)))
                elif distance <= radius + 0.01:
                    found.append((False, distance, f"{track.label} vertices {start}:{stop}", (k, start, stop)))
        return found

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
                    info = self.r.frames[frame]
                    result = place(_drawn_points(a.reference[rows], track.radii, rows), info.shapes,
                                   self._inertial(frame), tolerance=self.tolerance, mesh=info.mesh, visuals=info.visuals)
                    self._placements.append((track, a, int(frame), rows, result))
        return self._placements

    def pictured(self) -> Verdict:
        from conformance.apps import pictured

        return pictured.check(self)

    def placed(self) -> Verdict:
        self.placed_done = True
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
                result = place(_drawn_points(a.reference[rows], track.radii, rows), info.shapes, self._inertial(frame),
                               tolerance=self.tolerance, mesh=info.mesh, visuals=info.visuals)
            if info.node >= 0:
                soft.setdefault((track.label, info.client, info.body, info.name), []).append(
                    (rows, frame, soft_bodies.off_node(self, a.reference[rows], frame)))
                continue
            where = f"{track.label} vertices {vertex_ranges(rows)} held by {info.label}"
            # A welded frame holds what lies on its shape of its weld's drawings, a part, not a drawing of its own.
            if not result.judged and result.scale and frame not in at_its_size and self.welds[frame] < 0:
                verdict.passed = False
                verdict.lines.append(f"{where}: {result.why.removeprefix('not judged: ')}, and nothing draws it at its size")
                verdict.diagnosed("scaled")
            elif not result.judged:
                verdict.notes.append(f"{where}: {result.why}")
            elif not result.ok:
                verdict.passed = False
                diagnosis = result.diagnosis or self._other_body(result.offset, frame)
                if diagnosis == "other-body" and not self._on_another_frame(track, rows, frame):
                    diagnosis = ""  # far from its shape, and on no other: a mistake the catalogue does not tell
                verdict.lines.append(f"{where}: {result.why}")
                verdict.diagnosed(diagnosis)
        soft_bodies.placed(self, soft, verdict)
        return verdict

    def _inertial(self, frame: int) -> np.ndarray:
        return np.asarray(self.r.frames[frame].inertial, dtype=np.float64)

    def _on_another_frame(self, track, rows, frame: int) -> bool:
        """Whether the part of the drawing of ``rows`` (held by ``frame``) that lies off ``frame``'s shapes at the
        first tick lies on another frame's shapes instead, its centre in them: the evidence that it was paired
        with another body (a range counted wrong draws one body's shape at the other's place where it was
        built, then carries it with the wrong pose). A drawing far from its shape for another reason (a scale
        applied twice, a frame composed wrong) lies on none, or is centred on its own."""
        def local(points, f):
            return attach_mod.in_frame(points[None], self.pos[:1, f], self.rot[:1, f])[0]

        def reach(points):
            return max(float(np.max(np.linalg.norm(points - points.mean(axis=0), axis=1))), 1e-9)

        points = track.vertices[1, rows]
        off = points[self._outside(frame, local(points, frame)) > ON_SHAPE * reach(points)]
        if not len(off):
            return False
        centre, slack = off.mean(axis=0, keepdims=True), ON_SHAPE * reach(off)
        if float(self._outside(frame, local(centre, frame))[0]) <= slack:
            return False
        for other, info in enumerate(self.r.frames):
            if other == frame or info.node >= 0 or not (info.shapes or info.visuals):
                continue
            if float(self._outside(other, local(centre, other))[0]) <= slack and \
                    float(np.mean(self._outside(other, local(off, other)))) <= slack:
                return True
        return False

    def _other_body(self, offset, frame) -> str:
        return "other-body" if offset is not None and np.linalg.norm(offset) > bounding_radius(self.r.frames[frame].shapes) else ""

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
            for start, stop in _runs(bad, frames):
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


def _bad_ticks(error: np.ndarray, allowance: np.ndarray) -> np.ndarray:
    """The ticks (indices) at which some vertex's error ``(m, T)`` is beyond its allowance ``(m,)``."""
    return np.flatnonzero(np.any(error > allowance[:, None], axis=0))


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
