"""Sync order: whatever the order of steps, syncs, events and renders, a sync draws pyBullet's current state.

The other checks call the sync once after every step, or once after several. Real programs do not: a
render loop calls it faster than the physics runs (two calls, no step between), a physics timer steps
several times between two renders, the program teleports bodies, kicks them, resets joints, makes a
body static or dynamic (``changeDynamics(mass=…)``, pyBullet Quickstart Guide) and changes the time
step (``setTimeStep``) between calls. A Hypothesis state machine (``RuleBasedStateMachine``) does all
of these in any order; after every sync, every target must be drawn where pyBullet has it (vertices,
normals, every change announced: ``Kit.assert_frame``), and after a render each silhouette must match
pyBullet's own renderer's. That is the protocol's rules on order (README, "The sync protocol"; the
guide's timer callback syncs after ``p.stepSimulation()`` however often the timer fires): the sync
draws the current state whenever it is called, a second call without a step changes nothing, and
calls may be skipped between steps.
"""

from __future__ import annotations

import shlex

import pytest
from hypothesis import settings, strategies as st
from hypothesis.stateful import RuleBasedStateMachine, initialize, invariant, precondition, rule, run_state_machine_as_test

from conformance.checks import profiles, strategies, survey
from conformance.bullet.events import JointReset, Kick, Teleport
from conformance.checks.profiles import check_settings, stateful_steps
from conformance.checks.pytest_helpers import VERTEX_TARGET, Kit, _context

#: Scenes with a multibody's links (pendulum, wrecking_ball), shared actors (domino, wrecking_ball),
#: static bodies (all four) and bases with an inertial offset (weighted).
SCENES = ("pendulum", "domino", "wrecking_ball", "weighted")

#: ``setTimeStep`` values: the guide's 1/240 and rates either side, none so long that a scene blows up.
TIME_STEPS = (1 / 120, 1 / 240, 1 / 360, 1 / 480)

#: Mass given to a body built static when the machine makes it dynamic (pyBullet recomputes the inertia).
MADE_DYNAMIC = 1.0

CHECK = "test_sync_order_follows_any_order_of_calls"


class OrderFailure(AssertionError):
    """The state machine's failure: the kit's message, the calls that led to it, how to rerun."""

    def __init__(self, kind: str, message: str):
        super().__init__(message)
        self.kind = kind


def _without_reproduce(message: str) -> str:
    """The kit's frame message without its ``reproduce:`` line: ``conformance check`` replays steps and
    events, not an order of calls, so the machine says how to rerun itself instead."""
    return "\n".join(line for line in message.splitlines() if not line.startswith("reproduce: "))


def _short(values) -> str:
    """Numbers to 3 significant digits: the program in a message is for reading; Hypothesis prints it exactly."""
    return "(" + ", ".join(f"{v:.3g}" for v in values) + ")"


#: Calls a message lists: the last ones, which led to the failure (Hypothesis prints them all).
LAST_CALLS = 12


def rerun_command(scene: str, sync: str) -> str:
    """The run of this check on this scene again, under the Hypothesis profile in force (a derandomized
    profile replays the same programs; under the random default, Hypothesis' database replays the failing
    one where the run was made, and its ``@reproduce_failure`` line, printed with the failure, anywhere)."""
    from conformance.sync import own_scenes, printed

    return shlex.join([printed.python(), "-m", "pytest", "--pyargs", "conformance", "-p", "no:randomly", "-k",
                       f"{CHECK} and {scene}", "--sync", sync, *own_scenes.scene_arguments(scene),
                       "--hypothesis-profile", profiles._profile()])


def machine(kit: Kit, scene_name: str) -> type[RuleBasedStateMachine]:
    """The state machine over ``scene_name`` for the sync under ``kit``."""
    from conformance.rendering.silhouettes import silhouette_check

    # A default-mode Kit raises at the first wrong frame, which is what ends a Hypothesis example.
    checker = Kit(kit.implementation, kit.tolerance, survey=False)

    class SyncOrder(RuleBasedStateMachine):
        def __init__(self):
            super().__init__()
            self.run = None
            self._context = None
            self.calls: list[str] = []  # the program so far, for the failure message
            self.fresh = False  # synced since pyBullet last changed
            checker.closest = 0.0

        # -- the failure message -----------------------------------------------------------------
        def fail(self, kind: str, message: str) -> None:
            earlier = len(self.calls) - LAST_CALLS
            calls = "; ".join(self.calls[-LAST_CALLS:])
            calls = f"{earlier} calls, then {calls}" if earlier > 0 else calls
            raise OrderFailure(kind, f"{_without_reproduce(message)}\nafter the calls: {calls}\n"
                               f"rerun: {rerun_command(scene_name, kit.sync)}")

        def check(self) -> None:
            try:
                checker.assert_frame(self.run)
            except pytest.fail.Exception as failed:
                text = str(failed)
            else:
                return
            self.fail(survey.kind_of_failure(CHECK, text), text)  # outside the except: one paragraph, no chain

        def changed(self, call: str) -> None:
            self.calls.append(call)
            self.fresh = False

        def body(self, which: int) -> int:
            """The body an event's ``which`` names (as :mod:`conformance.bullet.events` picks it)."""
            return self.bodies[which % len(self.bodies)]

        def synced(self) -> None:
            self.run.sync()
            self.fresh = True

        # -- rules ---------------------------------------------------------------------------------
        @initialize(params=strategies.scene_parameters(scene_name))
        def start(self, params):
            self._context = checker.run(scene_name, **params)
            self.run = self._context.__enter__()  # built, and synced at frame 0
            self.bodies = sorted({b.body for b in self.run.scene.rigid})
            self.built_mass = {b: self.run.scene.p.getDynamicsInfo(b, -1)[0] for b in self.bodies}
            self.calls.append("start() [built, frame 0 synced]")
            self.fresh = True

        @rule(count=st.integers(1, 3))
        def step(self, count):
            for _ in range(count):
                self.run.step()
            self.changed(f"step({count})")

        @rule()
        def sync(self):
            self.calls.append("sync()")
            self.synced()

        @rule()
        def sync_twice(self):
            # The first call is checked too: a sync may be wrong after either.
            self.calls.append("sync_twice() [first]")
            self.synced()
            self.check()
            self.calls[-1] = "sync_twice()"
            self.synced()

        @rule(which=st.integers(0, 1000), offset=strategies.offsets(), orientation=strategies.orientations())
        def teleport(self, which, offset, orientation):
            self.run.apply_event(Teleport(self.run.frame, which, offset, orientation))
            self.changed(f"teleport(body {self.body(which)}, by {_short(offset)}, to {_short(orientation)})")

        @rule(which=st.integers(0, 1000), velocity=strategies.offsets(3.0), offset=strategies.offsets(0.05),
              spin=strategies.offsets(20.0))
        def kick(self, which, velocity, offset, spin):
            self.run.apply_event(Kick(self.run.frame, which, velocity, offset, spin))
            self.changed(f"kick(body {self.body(which)}, {_short(velocity)} m/s, {_short(spin)} rad/s)")

        @rule(which=st.integers(0, 1000), value=st.floats(-3.14, 3.14), orientation=strategies.orientations())
        def reset_joint(self, which, value, orientation):
            self.run.apply_event(JointReset(self.run.frame, which, value, orientation))
            self.changed(f"reset_joint(joint #{which}, {value:.3g} or {_short(orientation)})")

        @rule(which=st.integers(0, 1000), to_static=st.booleans())
        def toggle_static(self, which, to_static):
            # Mass 0 makes a dynamic body static, mass > 0 a static one dynamic (pyBullet recomputes the
            # inertia). Chosen among the bodies that can change that way, so a scene's one static ground
            # is made dynamic as often as any of its many dynamic bodies is made static.
            p = self.run.scene.p
            can = [b for b in self.bodies if (p.getDynamicsInfo(b, -1)[0] > 0) == to_static]
            if not can:
                return
            body = can[which % len(can)]
            mass = 0.0 if to_static else (self.built_mass[body] or MADE_DYNAMIC)
            p.changeDynamics(body, -1, mass=mass)
            self.changed(f"toggle_static(body {body}, mass={mass:.3g})")

        # Two changes of the time step in a row, or two renders of one sync, test nothing the first did not.
        @precondition(lambda self: not self.calls[-1].startswith("change_time_step"))
        @rule(dt=st.sampled_from(TIME_STEPS))
        def change_time_step(self, dt):
            self.run.scene.p.setTimeStep(dt)
            self.run.scene.dt = dt  # what the scene's actions and the kicks size themselves by
            self.changed(f"change_time_step({dt:.6g})")

        @precondition(lambda self: self.fresh and not self.calls[-1].startswith("render"))
        @rule()
        def render(self):
            self.calls.append("render()")
            record = silhouette_check(self.run, kit.sync, check=f"{CHECK}[{scene_name}]", tolerance=kit.tolerance)
            if not record.passed:
                self.fail("silhouette", f"{record.message} {_context(self.run, kit.sync, self.run.frame)}")

        # -- what must hold ------------------------------------------------------------------------
        @invariant()
        def drawn_where_pybullet_has_it(self):
            if self.run is not None and self.fresh:
                self.check()

        def teardown(self):
            if self._context is not None:
                self._context.__exit__(None, None, None)
            profiles.aim(checker.closest, VERTEX_TARGET)

    SyncOrder.__name__ = SyncOrder.__qualname__ = f"SyncOrder_{scene_name}"
    return SyncOrder


def check_order(kit: Kit, scene_name: str, examples: int = 3) -> None:
    """Run the machine over ``scene_name``; a failure fails the check with its kind and message."""
    __tracebackhide__ = True
    config = settings(check_settings(examples=examples), stateful_step_count=stateful_steps())
    try:
        run_state_machine_as_test(machine(kit, scene_name), settings=config)
    except OrderFailure as failure:
        found = failure
    else:
        return
    # Hypothesis' notes: the failing program as code (shrunk under ci) and a blob that replays it.
    program = "\n".join(getattr(found, "__notes__", ()))
    message = f"{found}\n{program}" if program else str(found)
    numbers = survey.figure_from_message(found.kind, message)
    kit.fail(found.kind, message, value=numbers["value"], limit=numbers["limit"], unit=numbers["unit"],
             at_least=numbers["at_least"], frame=numbers["frame"])


@pytest.mark.draws
@pytest.mark.parametrize("scene_name", [pytest.param(n, id=n, marks=pytest.mark.scene(n)) for n in SCENES])
def test_sync_order_follows_any_order_of_calls(scene_name, kit):
    """Steps (1 to 3 between syncs), syncs, two syncs with no step between, teleports, kicks, joint
    resets, bodies made static and dynamic again, a changed time step and renders, in any order: after
    every sync every target is drawn where pyBullet has it (normals turned, changes announced), and
    after a render every silhouette matches pyBullet's. Guarantees the protocol's rules on order
    (README, "The sync protocol")."""
    check_order(kit, scene_name)
