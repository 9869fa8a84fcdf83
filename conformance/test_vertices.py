"""Vertex conformance: after every frame, what FURY draws is where pybullet says each body is.

Ground truth is the kit's own (``conformance.bullet.truth``): each target's geometry captured in its link
frame when the actor was built, moved by pybullet's link-frame pose (base:
``getBasePositionAndOrientation`` with the inertial offset undone; link: ``getLinkState(...)[4:6]``
with forward kinematics); read-back is what the renderer will draw (FURY 0.12: polydata points through
the actor's full matrix; FURY 2: ``geometry.positions`` through ``actor.world.matrix``). The sync's own bookkeeping is never read. Every check looks at every frame it runs.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import example, given, strategies as st

from conformance import backends, figures, scenes
from conformance.checks import profiles, shared_run, strategies, twin
from conformance.judge import compare
from conformance.bullet.events import turning_everything
from conformance.checks.profiles import check_settings
from conformance.sync.printed import rerun_check
from conformance.checks.pytest_helpers import _context, bounds_figure, each_scene


def _scene_runs(scene_name: str, longest: int):
    """(parameters, frame count, events) for one scene, drawn together so events fit the run. At least one
    step: under flatmap Hypothesis draws frame 0 alone often, and with the default profile's four
    examples a sync drawing the previous step passed (``--hypothesis-seed=1``: 1 seed of 1–60 on
    free_fall); frame 0 alone is every other vertex check's first frame."""
    return strategies.scene_parameters(scene_name).flatmap(
        lambda params: strategies.frame_counts(longest, shortest=1).flatmap(
            lambda frames: st.tuples(st.just(params), st.just(frames),
                                     strategies.events(frames, soft=scenes.get(scene_name).deformable))))


def check_run(kit, scene_name: str, params: dict, frames: int, events=()) -> None:
    """The core of the frame checks: run ``frames`` frames with ``events``; check frame 0 and every frame after.
    Under Hypothesis the worst error in tolerances is the example's target, so the search climbs towards it."""
    with kit.aiming(), kit.run(scene_name, events=events, **params) as run:
        kit.assert_frame(run)
        for _ in run.frames(frames):
            kit.assert_frame(run)


def turned_everything(scene_name: str, params: dict, turns) -> list:
    """:func:`conformance.bullet.events.turning_everything` for every body of the scene built with ``params``."""
    with scenes.build(scene_name, **params) as probe:
        bodies = len({b.body for b in probe.rigid})
        soft = len({b.body for b in probe.bindings if b.soft})
    return turning_everything(bodies, turns, soft)


def with_scene_examples(scene_name: str, **fixed):
    """Hypothesis ``@example``s of a check: the scene's defaults and each of its ``examples``
    parameter sets (``SceneSpec.examples``), with the other arguments ``fixed``; tried first, every run."""

    def decorate(check):
        for params in ({}, *scenes.get(scene_name).examples):
            check = example(params=dict(params), **fixed)(check)
        return check

    return decorate


def check_every_frame_equals_once(kit, scene_name: str, params: dict, frames: int) -> None:
    """The core of the every-frame-vs-once check."""
    drawn = []
    for every_frame in (True, False):
        with kit.run(scene_name, **params) as run:
            for _ in range(frames):
                run.step()
                if every_frame:
                    run.sync()
            if not every_frame:
                run.sync()
            drawn.append({name: backends.world_vertices(a) for name, a in run.drawing.actors.items()})
            tolerance = max(r.tolerance for r in compare.compare_vertices(run.drawing, frames, kit.tolerance))
            context = _context(run, kit.sync, frames)
    gaps = {name: float(np.nan_to_num(np.abs(drawn[0][name] - drawn[1][name]), nan=np.inf).max()) for name in drawn[0]}
    profiles.aim(max(gaps.values(), default=0.0) / tolerance, "every frame vs once / tolerance")
    figures.note("every frame vs once", max(gaps.values(), default=0.0), tolerance, where=context)
    for name, gap in gaps.items():
        if not gap <= tolerance:
            kit.fail("every frame = once",
                     f"actor {name!r} is drawn {gap:.3g} m apart when synced every frame and when synced once after "
                     f"{frames} frames, but should agree within {tolerance:.3g} m {context}",
                     exception=AssertionError, value=gap, limit=tolerance, unit="m", frame=frames, target=name)


#: The frames of the default run the every-frame check looks at (the rest of a long scene is tumbling's).
EVERY_FRAME = 400


@shared_run.watcher("test_vertices_match_poses_every_frame", last=lambda spec: min(spec.steps, EVERY_FRAME))
def _every_frame(run, kit):
    kit.assert_frame(run)


@each_scene()
def test_vertices_match_poses_every_frame(scene_name, kit):
    """The scene with its own parameters (the guide's, for the guide's scenes), then with each of its
    ``examples``: every target, every frame of the default run, from frame 0 (right after set-up) on.
    (The default run is the scene's shared run, :mod:`conformance.checks.shared_run`.)"""
    spec = scenes.get(scene_name)
    shared_run.report(kit, "test_vertices_match_poses_every_frame", scene_name)
    for params in spec.examples:
        check_run(kit, scene_name, dict(params), min(spec.steps, EVERY_FRAME))


@pytest.mark.draws
@each_scene()
def test_vertices_match_through_teleports_and_kicks(scene_name, kit):
    """Hypothesis varies the scene's parameters, the run's length (1 frame up) and what happens
    between syncs: ``resetBasePositionAndOrientation`` to any orientation, ``resetJointState``,
    and forces and torques that set bodies moving and spinning; in a scene with soft bodies, also a soft
    body teleported and turned, or every node of it set moving (``resetBaseVelocity``)."""

    @check_settings(examples=4)
    @given(run_plan=_scene_runs(scene_name, longest=40))
    def check(run_plan):
        params, frames, events = run_plan
        check_run(kit, scene_name, params, frames, events)

    check()


@pytest.mark.draws
@each_scene()
def test_vertices_match_in_every_orientation(scene_name, kit):
    """Every body, soft ones too, teleported to an orientation drawn uniformly over rotations or from the cases that
    break sloppy code (identity, half turns, pitch at and near ±90°, negative w), every spherical
    joint turned likewise, before the first sync; every body turned again after it; then a few
    frames of the motion that follows. Every hard case is always tried, on the scene's defaults and
    on each of its ``examples``."""

    @check_settings(examples=5)
    @with_scene_examples(scene_name, turns=list(strategies.HARD_ORIENTATIONS), frames=2)
    @given(params=strategies.scene_parameters(scene_name),
           turns=st.lists(strategies.orientations(), min_size=1, max_size=6),
           frames=st.integers(0, 3))
    def check(params, turns, frames):
        check_run(kit, scene_name, params, frames, turned_everything(scene_name, params, turns))

    check()


@shared_run.watcher("test_no_drift_over_ten_thousand_frames", last=lambda spec: 10_000, scenes=("tumbling",))
def _no_drift(run, kit):
    kit.assert_frame(run)


@pytest.mark.scene("tumbling")
def test_no_drift_over_ten_thousand_frames(kit):
    """Bodies tumbling through every attitude for 10,000 frames (42 s of simulated time), checked
    after every frame: an implementation that accumulates per-frame increments must keep its
    rounding within the same tolerance as one that computes each frame from the pose."""
    shared_run.report(kit, "test_no_drift_over_ten_thousand_frames", "tumbling")


@shared_run.watcher("test_sync_does_not_touch_physics", last=lambda spec: min(spec.steps, 30), physics=True)
def _physics_untouched(run, kit, before):
    after = run.scene.physics_state()
    if before != after:
        changed = [a.decode() for a, b in zip(before.splitlines(), after.splitlines()) if a != b]
        kit.fail("physics touched",
                 f"the sync changed pybullet's state: {changed[0][:300]} … [{run.scene.name}, frame {run.frame}, "
                 f"sync {kit.sync!r}] ({len(changed)} entries changed)",
                 value=len(changed), unit="entries changed", frame=run.frame)
    mirror = twin.of(run)
    unsynced = mirror.state(run.frame) if mirror.usable else before
    if unsynced != before:
        changed = [a.decode() for a, b in zip(before.splitlines(), unsynced.splitlines()) if a != b]
        kit.fail("physics touched",
                 f"the sync changed pybullet's state, and the step carried it on: after the step of frame {run.frame} "
                 f"it differs from the same scene's stepped without the sync: {changed[0][:300]} … [{run.scene.name}, "
                 f"frame {run.frame}, sync {kit.sync!r}] ({len(changed)} entries changed). The sync of frame "
                 f"{run.frame - 1} wrote to pybullet; a change pybullet does not report shows only here: a soft body's "
                 "node velocities (resetBaseVelocity), a force left pending (applyExternalForce acts at the next step)",
                 value=len(changed), unit="entries changed", frame=run.frame)


@each_scene()
def test_sync_does_not_touch_physics(scene_name, kit):
    """A sync only reads pybullet: every body's pose, velocity, joint states and dynamics and the
    engine parameters are bit-identical before and after each sync call, and after each step the same as
    the scene's stepped without the sync (:mod:`conformance.checks.twin`: what pyBullet does not report,
    a soft body's node velocities, a pending force), over the first 30 frames."""
    shared_run.report(kit, "test_sync_does_not_touch_physics", scene_name)


@shared_run.watcher("test_sync_keeps_the_mesh", last=lambda spec: min(spec.steps, 30))
def _mesh_kept(run, kit):
    for name, actor in run.drawing.actors.items():
        now = backends.mesh_signature(actor)
        if now != run.built_mesh[name]:
            what = [w for w, a, b in zip(("vertex count", "cells", "colours"), now, run.built_mesh[name]) if a != b]
            kit.fail("mesh", f"actor {name!r}: {', '.join(what)} changed, but a sync should only move vertices "
                     f"[{run.scene.name}, frame {run.frame}, sync {kit.sync!r}]", frame=run.frame, target=name)


@each_scene()
def test_sync_keeps_the_mesh(scene_name, kit):
    """A sync moves vertices and nothing else: every actor keeps its vertex count, its cells
    (topology) and its vertex colours, and the scene keeps its actors (the first 30 frames)."""
    shared_run.report(kit, "test_sync_keeps_the_mesh", scene_name)


@pytest.mark.draws
@each_scene()
def test_syncing_every_frame_equals_syncing_once(scene_name, kit):
    """Syncing after every step and syncing once after N steps draw the same vertices: a sync depends
    on the pose, not on having been called for each frame in between."""

    @check_settings(examples=2)
    @given(params=strategies.scene_parameters(scene_name), frames=st.integers(1, 30))
    def check(params, frames):
        check_every_frame_equals_once(kit, scene_name, params, frames)

    check()


@shared_run.watcher("test_drawn_bounds_agree_with_get_aabb", last=lambda spec: min(spec.steps, EVERY_FRAME))
def _bounds(run, kit):
    steps = min(run.scene.steps, EVERY_FRAME)
    if run.frame not in (0, steps // 2, steps):
        return
    for failure in (r for r in compare.compare_bounds(run.drawing, run.frame, kit.tolerance) if not r.ok):
        kit.fail("bounds", f"{failure.target!r}: {'; '.join(failure.problems)} {_context(run, kit.sync, run.frame)}\n"
                 f"reproduce: {rerun_check(f'test_drawn_bounds_agree_with_get_aabb[{run.scene.name}]', run.scene.name, kit.sync, kit.tolerance)}",
                 frame=run.frame, target=failure.target, **bounds_figure(failure.problems))


@each_scene()
def test_drawn_bounds_agree_with_get_aabb(scene_name, kit):
    """Each drawn body's world bounding box lies inside pybullet's ``getAABB`` and reaches it on every
    side within the stated margin (see ``conformance.judge.tolerances``), at the first, middle and last frame."""
    shared_run.report(kit, "test_drawn_bounds_agree_with_get_aabb", scene_name)
