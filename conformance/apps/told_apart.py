"""Telling a late sync from one that draws before the app's own moves, where the app's own run cannot.

A program that plays a trajectory back steps, then poses its joints with ``resetJointState``, then draws.
Drawn a tick behind, it made one of two mistakes: its sync runs before ``p.stepSimulation()``
(``previous-step``) or between the step and its own resets (``before-own-move``). The fixes differ, and
so does the order of calls the user is told to look at. But after ``resetJointState`` a step leaves the
joints exactly where they were (pybullet 3.2.7, measured on the zoo's playback programs: 0.0 m between the
pose before the step and the pose after it), so both mistakes draw the same vertices and the judge can only
say ``late-or-own-move``.

The kit tells them apart as it tells a late copy from a copy made once (sync mode): by a run that makes
them differ. Right after the step of ticks 1, 2 and 3, before the app's own code reads, the kit resets every
joint and turns every dynamic body (:class:`~conformance.apps.perturb.AfterStep` events). A sync that runs
between the step and the app's own moves draws the kit's pose; one that runs before the step never sees
it; a right one draws what the app's moves made of it. For each piece the judge named with the tie, the
kit looks at which of the two poses holds it through that run (:func:`shown`: a few array operations, where
judging the run again cost a minute on a racecar whose every joint the kit had turned). Their one answer
replaces the tie; none, or two different ones, leave it, which names neither.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from conformance.apps import attachment
from conformance.apps.verdict import DIAGNOSES

__all__ = ["TIE", "TICKS", "moves", "settle", "shown"]

#: the judge's name for the two mistakes it cannot tell apart on the app's own run
TIE = "late-or-own-move"
#: the names the telling run may settle it on
SETTLED = ("before-own-move", "previous-step")
#: ticks of the telling run: its moves fall in ticks 1 to 3
TICKS = 5


def moves(frames) -> list:
    """The kit's moves of the telling run, for the pyBullet frames ``frames`` of the app: every joint reset
    (to 1.0, -0.7 and 0.4 at ticks 1, 2 and 3: values a trajectory is unlikely to hold at all three) and every
    dynamic body turned, each right after the tick's step. From tick 1: a playback whose trajectory moves at an
    even pace drawn a tick late is held by its frame at a fixed offset from tick 2 on, so the first tick is
    where its drawing is judged wrong, and where the kit's move must be."""
    from conformance.apps.perturb import AfterStep
    from conformance.bullet.events import JointReset, Teleport
    from conformance.checks.strategies import HARD_ORIENTATIONS

    clients = {f.client for f in frames}
    joints = max((sum(1 for f in frames if f.client == c and f.link >= 0 and f.node < 0) for c in clients), default=0)
    bodies = max((sum(1 for f in frames if f.client == c and f.link == -1 and f.node < 0 and f.mass > 0)
                  for c in clients), default=0)
    found = []
    for tick, value, turn in ((1, 1.0, HARD_ORIENTATIONS[8]), (2, -0.7, HARD_ORIENTATIONS[11]),
                              (3, 0.4, HARD_ORIENTATIONS[17])):
        found += [AfterStep(JointReset(frame=tick, which=j, value=value, orientation=turn)) for j in range(joints)]
        found += [AfterStep(Teleport(frame=tick, which=b, offset=(0.0, 0.0, 0.0), orientation=turn))
                  for b in range(bodies)]
    return found


def settle(result, *, reproduce, timeout: float | None = None) -> str:
    """Replace the tie in ``result``'s verdicts (an :class:`~conformance.apps.AppResult`) by the mistake a
    telling run shows; return that name, or "" when there was no tie or it stays. ``reproduce(script, ticks,
    events, tick_function)`` is the command that runs the telling run again, for the note."""
    from conformance.apps import launch, perturb

    ties = [tie for v in result.verdicts.values() for tie in v.ties]
    if not ties:
        return ""
    events = [perturb.as_dict(e) for e in moves(result.recording.frames)]
    kwargs = {} if timeout is None else {"timeout": timeout}
    try:
        recording = launch.record(result.script, ticks=TICKS, events=events, tick_function=result.tick_function,
                                  **kwargs)
    except (launch.AppFailed, launch.KitFailed):
        return ""  # the telling run did not finish: the tie names neither, which is true
    found = {shown(recording, *tie) for tie in ties} - {""}
    if len(found) != 1:
        return ""
    name = found.pop()
    command = reproduce(result.script, TICKS, events, result.tick_function)
    for verdict in result.verdicts.values():
        if TIE not in verdict.diagnoses:
            continue
        verdict.diagnoses = [name if d == TIE else d for d in verdict.diagnoses]
        verdict.lines = [f"    diagnosis: {DIAGNOSES[name]}" if line == f"    diagnosis: {DIAGNOSES[TIE]}" else line
                         for line in verdict.lines]
        verdict.notes.append(f"{name}, not {SETTLED[SETTLED.index(name) - 1]}: told apart by a run in which the kit "
                             f"reset every joint and turned every body right after the step of ticks 1 to 3: the sync "
                             f"{'drew' if name == 'before-own-move' else 'never drew'} the kit's pose ({command})")
    return name


def shown(recording, actor: int, start: int, stop: int, frame: int) -> str:
    """Which of the two poses holds the piece ``start:stop`` of ``actor`` in the telling run: the frame's pose
    before the app's first write of each tick (the kit's, at its ticks), or its pose before the tick's step.
    The one that holds it keeps its vertices in one place of its frame at every tick; the other lets them go
    with the kit's move. "" when neither, or both (the kit's move left this frame where it was)."""
    if actor >= len(recording.actors) or frame >= len(recording.frames) or recording.writes is None:
        return ""
    vertices = recording.actors[actor].vertices[1:, start:stop]
    if vertices.shape[1] != stop - start or not np.isfinite(vertices).all():
        return ""
    end = np.concatenate([recording.positions[1:, frame], recording.orientations[1:, frame]], axis=-1)
    written = recording.writes[1:, frame, :7]
    own = np.where(np.isfinite(written).all(axis=-1)[:, None], written, end)
    late = np.concatenate([recording.before_positions[1:, frame], recording.before_orientations[1:, frame]], axis=-1)

    def spread(pose) -> float:
        local = attachment.local_coordinates(vertices, pose[:, None, :3],
                                             Rotation.from_quat(pose[:, 3:7]).as_matrix()[:, None])
        return float(np.max(np.linalg.norm(local - np.median(local, axis=0), axis=-1)))

    apart = {name: spread(pose) for name, pose in zip(SETTLED, (own, late))}
    # the one that holds it must do so ten times better than the other: a move of the kit's shows by
    # centimetres, a vertex held by float rounding, by micrometres
    for name, other in (SETTLED, SETTLED[::-1]):
        if apart[name] * 10 < apart[other] and apart[other] > 1e-4:
            return name
    return ""
