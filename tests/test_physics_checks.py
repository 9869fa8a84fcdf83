"""Each physics check fails, with a readable message, when its premise is broken on purpose: a filter
set the wrong way, a force applied in the other frame, a wrong mass, a coefficient set on one body
only. The deviation list and the documented-vs-observed table agree with the installed pybullet."""

from __future__ import annotations

import inspect

import numpy as np
import pytest
from hypothesis import given, settings

from conformance import sync
from conformance.checks import documented, strategies
from conformance.bullet import collisions, deviations, physics
from conformance import test_filters as filters
from conformance import test_forces as forces
from conformance import test_materials as materials
from conformance.bullet.collisions import FilterMode, GroupMask, PairFilter
from conformance.bullet.physics import Push

Failed = pytest.fail.Exception

CROSSING = dict(kind="sphere", size_a=0.15, size_b=0.2, mass_a=1.0, mass_b=2.0, speed=1.5, gap=0.4,
                restitution=0.8, link=False, collide=True, seed=0)
LINKED = {**CROSSING, "kind": "box", "link": True, "seed": 3}
ONE_WAY = (1, 2, 2, 4)  # AND says pass, OR says collide
TURNED = dict(kind="box", size=0.3, mass=2.0, orientation=(0.3, 0.2, 0.1, 0.927), spin=(1.0, 2.0, 3.0))
FORCE, LEVER, TORQUE = (3.0, -5.0, 7.0), (0.1, 0.05, -0.07), (0.05, -0.1, 0.08)
PENDULUM = dict(length=1.0, radius=0.15, mass=1.0, angle=0.6, links=1)
SLIDE = dict(size=0.2, mass=1.0, speed=2.0, box_friction=0.5, ground_friction=0.6)


# -- the checks pass on the premise they state -------------------------------------------------
def test_core_checks_pass_on_their_own_premise():
    filters.verify_collision(CROSSING, [], expected=True, why="default")
    filters.verify_collision(LINKED, [PairFilter(0, swapped=True)], expected=False, why="pair disabled")
    forces.verify_push(TURNED, [Push(FORCE, "LINK_FRAME", LEVER)])
    forces.verify_link_push(PENDULUM, Push(FORCE, "LINK_FRAME", (0.02, 0.0, 0.01)))
    materials.verify_free_fall(TURNED, 1 / 100, 3)
    materials.verify_bounce(100, 0.9, 0.8, 0.1, 1.0)
    materials.verify_sliding(SLIDE)


# -- collision filters -------------------------------------------------------------------------
def test_default_collision_check_fails_when_the_pair_is_disabled():
    with pytest.raises(Failed, match=r"outcome: no contact points; a ended past b .*but should collide .*"
                                     r"\[crossing\(kind='sphere'.*setCollisionFilterPair\(a, b, -1, -1, 0\) before step 0"):
        filters.verify_collision(CROSSING, [PairFilter(0)], expected=True, why="no filter calls")


def test_pair_filter_check_fails_when_the_filter_is_set_the_wrong_way():
    # The check expects the last call (enable=0) to win; the premise applies enable=1 instead.
    with pytest.raises(Failed, match=r"outcome: contact points after frames \d+.*but should pass through"):
        filters.verify_collision(CROSSING, [PairFilter(0), PairFilter(1, step=2)], expected=False,
                                 why="the last setCollisionFilterPair has enableCollision=0")


def test_pair_filter_check_fails_when_the_rule_names_the_wrong_link():
    # b's shape is on link 0 of its multibody; a rule naming its base (-1) filters nothing.
    with pytest.raises(Failed, match=r"but should pass through .*\[crossing\(kind='box'.*link=True.*"
                                     r"setCollisionFilterPair\(a, b, -1, -1, 0\) before step 0"):
        filters.verify_collision(LINKED, [PairFilter(0, link_b=-1)], expected=False, why="pair disabled")


def test_group_mask_check_fails_with_the_other_modes_rule():
    calls = filters.group_mask_calls(ONE_WAY, collisions.AND_MODE)
    wrong = collisions.group_mask_rule(collisions.OR_MODE, *ONE_WAY)
    with pytest.raises(Failed, match=r"but should collide .*collisionFilterMode=0"):
        filters.verify_collision(CROSSING, calls, expected=wrong, why="OR rule applied to mode 0")


def test_default_mode_check_passes_once_the_documented_mode_is_set():
    # The expected failure is pybullet's default alone: with mode 0 set, the same check passes...
    filters.verify_collision(CROSSING, filters.group_mask_calls(ONE_WAY, collisions.AND_MODE), expected=False,
                             why="mode 0 set explicitly")
    # ...and without it, on this pybullet, it fails as the deviation list says.
    if deviations.applies("default-collision-filter-mode"):
        with pytest.raises(Failed, match="but should pass through"):
            filters.test_default_filter_mode_is_and()


def test_override_check_fails_without_the_pair_rule():
    # Masks that exclude each other: only the pair rule (enable=1) would make them collide.
    calls = [FilterMode(0), GroupMask("a", 1, 0), GroupMask("b", 2, 0)]
    with pytest.raises(Failed, match="but should collide"):
        filters.verify_collision(CROSSING, calls, expected=True, why="pair rule enableCollision=1 left out")


def test_render_check_fails_when_the_sync_hides_the_pass_through():
    with pytest.raises(Failed, match=r"drawn centre of a, b outside the other body's drawn shape .*"
                                     r"should be drawn overlapping \[crossing\(.*frame \d+; sync 'physics_syncs:KeepsApart'\]"):
        filters.verify_drawn_overlap({**CROSSING, "collide": False}, sync.load("physics_syncs:KeepsApart"))


def test_render_check_fails_when_physics_does_not_pass_through():
    with pytest.raises(Failed, match=r"contact points after frames \d+.*, but should be none"):
        filters.verify_drawn_overlap(CROSSING, sync.load("reference"))


def test_render_check_fails_when_the_sync_does_not_move_the_bodies():
    with pytest.raises(Failed, match=r"drawn centre of|is drawn at .* but should be at"):
        filters.verify_drawn_overlap({**CROSSING, "collide": False}, sync.load("wrong_syncs:DoesNothing"))


def test_a_pair_drawn_apart_by_a_known_mistake_is_told_which():
    """The last body never moved (an off-by-one in the loop over bodies) draws the pair apart: the failure
    names that mistake on its second line (issue 48), as the vertex checks would."""
    with pytest.raises(Failed, match=r"drawn centre of .*\ndiagnosis: drawn where it was built"):
        filters.verify_drawn_overlap({**CROSSING, "collide": False}, sync.load("wrong_syncs:SkipsLastTarget"))


# -- forces and torques ------------------------------------------------------------------------
@pytest.mark.parametrize("applied, assumed", [("LINK_FRAME", "WORLD_FRAME"), ("WORLD_FRAME", "LINK_FRAME")])
def test_force_check_fails_when_the_force_is_applied_in_the_other_frame(applied, assumed):
    with pytest.raises(Failed, match=rf"Δv=\(.*\), but should be ΣF·dt/m \+ g·dt = .*\[free_fall\(kind='box'.*"
                                     rf"step 1; applyExternalForce\(forceObj=\(3, -5, 7\), posObj=.*{applied}\)\]"):
        forces.verify_push(TURNED, [Push(FORCE, applied, LEVER)], expected_pushes=[Push(FORCE, assumed, LEVER)])


def test_force_check_fails_with_a_wrong_mass():
    with pytest.raises(Failed, match=r"Δv=.*but should be ΣF·dt/m"):
        forces.verify_push(TURNED, [Push(FORCE, "WORLD_FRAME", LEVER)], mass=2.0 * TURNED["mass"])


def test_force_check_fails_when_the_lever_arm_is_ignored():
    with pytest.raises(Failed, match=r"Δω=.*but should be I⁻¹·Σ\(τ \+ r×F\)·dt"):
        forces.verify_push(TURNED, [Push(FORCE, "WORLD_FRAME", LEVER)],
                           expected_pushes=[Push(FORCE, "WORLD_FRAME", (0.0, 0.0, 0.0))])


def test_torque_check_fails_when_the_torque_is_applied_in_the_other_frame():
    with pytest.raises(Failed, match=r"Δω=.*but should be I⁻¹·Σ\(τ \+ r×F\)·dt.*applyExternalTorque"):
        forces.verify_push(TURNED, [Push(TORQUE, "LINK_FRAME", None)], expected_pushes=[Push(TORQUE, "WORLD_FRAME", None)])


def test_lifetime_check_fails_when_the_push_persists():
    sphere = {**TURNED, "kind": "sphere"}
    with pytest.raises(Failed, match=r"Δv=.*but should be g·dt \(the push is cleared\).*step 2.*before steps 1 and 2"):
        forces.verify_push_lifetime(sphere, [Push(FORCE, "WORLD_FRAME", LEVER)], repeat=True)


def test_sum_check_fails_when_a_push_is_left_out():
    pushes = [Push(FORCE, "WORLD_FRAME", LEVER), Push(FORCE, "LINK_FRAME", (0.0, 0.0, 0.0))]
    with pytest.raises(Failed, match=r"Δv=.*but should be ΣF·dt/m"):
        forces.verify_push(TURNED, pushes, expected_pushes=pushes[:1])


def test_substep_check_fails_if_the_push_lasted_one_substep():
    push = Push(FORCE, "WORLD_FRAME", LEVER)
    first_only = Push(tuple(c / 4 for c in FORCE), "WORLD_FRAME", LEVER)
    with pytest.raises(Failed, match=r"Δv=.*step 1 of 4 sub-steps"):
        forces.verify_push(TURNED, [push], expected_pushes=[first_only], substeps=4, spin=False)


@pytest.mark.parametrize("snippet", ["applyExternalForce", "applyExternalTorque"])
def test_guide_snippet_check_fails_with_a_wrong_mass(snippet):
    with pytest.raises(Failed, match=r"Δ[vω]=.*but should be"):
        forces.verify_guide_snippet(snippet, "off", assumed_mass=1.0)


@pytest.mark.parametrize("applied, assumed", [("LINK_FRAME", "WORLD_FRAME"), ("WORLD_FRAME", "LINK_FRAME")])
def test_link_force_check_fails_in_the_other_frame(applied, assumed):
    lever = (0.02, 0.0, 0.01)
    with pytest.raises(Failed, match=r"Δq̇=.*but should be \(\(posObj − hinge\) × F\)·axis·dt.*\[pendulum\(.*on link 0\]"):
        forces.verify_link_push(PENDULUM, Push(FORCE, applied, lever), expected_push=Push(FORCE, assumed, lever))


def test_raised_clamp_check_fails_with_the_default_clamp():
    gain = (250.0, 0.0, 0.0)
    with pytest.raises(Failed, match=r"Δv=\(100, .*but should be F·dt/m \+ g·dt = \(250, .*maxJointVelocity default"):
        forces.verify_clamped_push(TURNED, gain, max_joint_velocity=None)
    forces.verify_clamped_push(TURNED, gain, max_joint_velocity=1000.0)


def test_clamp_deviation_is_observed_on_this_pybullet():
    if not deviations.applies("velocity-clamp-on-free-base"):
        pytest.fail("velocity-clamp-on-free-base is not listed for this pybullet: measure it and update deviations.py")
    with pytest.raises(Failed, match=r"Δv=\(100, 0, -0.0416666667\), but should be F·dt/m \+ g·dt = \(333.33"):
        forces.test_free_base_is_not_clamped()


# -- gravity, time step, damping, materials ----------------------------------------------------
def test_free_fall_check_fails_with_a_wrong_time_step():
    with pytest.raises(Failed, match=r"vz=-0.1, but should be g·h·m \(h = dt/k, m sub-steps taken\) = -0.0416666667 .*\[free_fall\(.*step 1; setTimeStep\(0.01\)"):
        materials.verify_free_fall(TURNED, 1 / 100, 1, assumed_dt=1 / 240)


def test_free_fall_check_fails_when_sub_steps_are_ignored():
    with pytest.raises(Failed, match=r"z=.*but should be z0 \+ g·\(dt/k\)²·m\(m\+1\)/2"):
        # The premise broken: the closed form of one step of dt, although 4 sub-steps are set.
        materials.verify_free_fall(TURNED, 1 / 100, 4, assumed_substeps=1)


def test_lost_sub_steps_are_bullets_clock_not_a_failure():
    """For some time steps Bullet's sub-step clock falls just short and a sub-step is lost: the law
    counts them as Bullet does (found by Hypothesis: dt = 0.0146824…, 3 sub-steps, failed before)."""
    lossy = next(dt for dt in np.linspace(0.001, 0.02, 4001)
                 if physics.substeps_taken(dt, 3, 60) != 180)
    assert physics.substeps_taken(lossy, 3, 60) < 180
    materials.verify_free_fall(TURNED, lossy, 3)  # pybullet really takes fewer sub-steps, and the law agrees


def test_engine_defaults_check_fails_when_gravity_is_set():
    with pytest.raises(Failed, match=r"v=.*but should be 0 \(no gravity\).*setGravity\(0, 0, -10\)"):
        materials.verify_engine_defaults(1.0, 0.1, 10, gravity=(0, 0, -10))


def test_damping_check_fails_with_a_wrong_coefficient():
    sphere = {**TURNED, "kind": "sphere"}
    with pytest.raises(Failed, match=r"v=.*but should be v \+ \(g − k·\(1 \+ \|v\|\)·v\)·dt"):
        materials.verify_damping(sphere, 0.1, 0.2, (1.0, -2.0, 0.5), (0.0, 0.0, 0.0), assumed=(0.04, 0.2))


def test_default_damping_check_fails_when_the_default_is_not_the_documented_one():
    with pytest.raises(Failed, match=r"v=.*but should be the 0-damped twin's"):
        materials.verify_default_damping(1.0, 0.2, (2.0, 0.0, 0.0), (0.0, 0.0, 3.0), maximal=False, documented=0.0)


def test_maximal_damping_deviation_is_observed_on_this_pybullet():
    if not deviations.applies("maximal-coordinates-damping-default"):
        pytest.fail("maximal-coordinates-damping-default is not listed for this pybullet: measure it")
    with pytest.raises(Failed, match=r"v=.*but should be the 0.04-damped twin's .*maximal-coordinate"):
        materials.verify_default_damping(1.0, 0.2, (2.0, 0.0, 0.0), (0.0, 0.0, 3.0), maximal=True)
    # What pybullet does instead: start undamped.
    materials.verify_default_damping(1.0, 0.2, (2.0, 0.0, 0.0), (0.0, 0.0, 3.0), maximal=True, documented=0.0)


def test_bounce_check_fails_when_one_coefficient_is_taken_for_the_pair():
    with pytest.raises(Failed, match=r"apex/drop=0.5.*, but should be in \[0.81, 0.86\].*\[bouncing_ball\("):
        materials.verify_bounce(100, 0.9, 0.8, 0.1, 1.0, expected_e=0.9)


def test_one_coefficient_check_fails_when_both_are_set():
    with pytest.raises(Failed, match=r"apex/drop=0.5.*, but should be in \[0, 0.001\] \(no bounce"):
        materials.verify_bounce(100, 0.9, 0.8, 0.1, 1.0, expected_e=0.0)


def test_friction_check_fails_when_one_coefficient_is_taken_for_the_pair():
    with pytest.raises(Failed, match=r"deceleration=3.*but should be μ·g with μ = 0.5 = 5"):
        materials.verify_sliding(SLIDE, expected_mu=SLIDE["box_friction"])


def test_frictionless_check_fails_when_the_plate_has_friction():
    with pytest.raises(Failed, match=r"vx=.*but should be the launch speed"):
        materials.verify_frictionless(SLIDE, ground_friction=0.6)


# -- strategies the checks rely on -------------------------------------------------------------
@settings(max_examples=50, deadline=None)
@given(masks=strategies.one_way_group_masks())
def test_one_way_masks_always_tell_and_from_or(masks):
    assert collisions.group_mask_rule(collisions.OR_MODE, *masks)
    assert not collisions.group_mask_rule(collisions.AND_MODE, *masks)


@settings(max_examples=50, deadline=None)
@given(gain=strategies.speed_gains())
def test_speed_gains_always_pass_the_clamp(gain):
    assert max(abs(c) for c in gain) >= 105.0


def test_group_mask_rule_is_the_quickstart_table():
    # "(group A&maskB) AND (groupB&maskA)" and "... OR ...", bit by bit.
    assert collisions.group_mask_rule(0, 1, 2, 2, 1) and collisions.group_mask_rule(1, 1, 2, 2, 1)
    assert not collisions.group_mask_rule(0, *ONE_WAY) and collisions.group_mask_rule(1, *ONE_WAY)
    assert not collisions.group_mask_rule(1, 1, 1, 2, 2)
    assert collisions.group_mask_rule(0, -1, -1, 4, -1)


# -- the deviation list and the documented-vs-observed table -----------------------------------
MODULES = {"conformance/test_filters.py": filters, "conformance/test_forces.py": forces,
           "conformance/test_materials.py": materials}


@pytest.mark.parametrize("deviation", deviations.DEVIATIONS, ids=lambda d: d.id)
def test_every_deviation_marks_its_check(deviation):
    path, _, name = deviation.check.partition("::")
    check = getattr(MODULES[path], name)
    marks = [m for m in getattr(check, "pytestmark", []) if m.name == "xfail"]
    assert marks and marks[0].kwargs["strict"] is True, f"{deviation.check} carries no strict xfail"
    assert deviation.id in marks[0].kwargs["reason"], f"{deviation.check}'s xfail is not keyed to {deviation.id!r}"
    assert deviation.id in inspect.getdoc(check), f"{deviation.check}'s docstring does not name {deviation.id!r}"


def test_every_expected_failure_in_the_checks_is_listed():
    for module in MODULES.values():
        for name, check in vars(module).items():
            for mark in getattr(check, "pytestmark", []):
                if mark.name == "xfail":
                    reason = mark.kwargs["reason"]
                    assert any(d.id in reason and d.check.endswith(f"::{name}") for d in deviations.DEVIATIONS), (
                        f"{module.__name__}.{name} is an expected failure not listed in conformance/bullet/deviations.py")


def test_deviations_are_keyed_by_version():
    deviation = deviations.get("default-collision-filter-mode")
    assert deviation.applies("3.2.7") and deviation.applies("3.2.5") and not deviation.applies("3.2.4")
    mark = deviations.expected_failure("default-collision-filter-mode", version="3.2.4")
    assert mark.args == (False,) and mark.kwargs["strict"] is True
    reason = deviations.expected_failure("default-collision-filter-mode", version="3.2.7").kwargs["reason"]
    assert "bullet3 issue #4148" in reason and "(group A&maskB) AND (groupB&maskA)" in reason
    with pytest.raises(KeyError, match="should be one of"):
        deviations.get("no-such-deviation")


def test_documented_table_agrees_with_the_deviation_list():
    measured = documented.rows()
    unexpected = [f"{r.statement.id}: {r.verdict} ({r.observed})" for r in measured if r.unexpected]
    assert not unexpected, "documented vs observed disagrees with conformance/bullet/deviations.py:\n" + "\n".join(unexpected)
    listed = {r.statement.deviation for r in measured if r.statement.deviation}
    assert listed == {d.id for d in deviations.DEVIATIONS}, "every listed deviation needs a row in the table"


def test_documented_table_reports_a_vanished_or_unlisted_deviation():
    statement = next(s for s in documented.STATEMENTS if s.deviation == "default-collision-filter-mode")
    assert documented._verdict(statement, True, "3.2.7") == "as documented, but listed: `default-collision-filter-mode`"
    assert documented._verdict(statement, False, "3.2.4") == "DEVIATES, NOT LISTED"
    assert documented._verdict(statement, False, "3.2.7") == "deviates (listed: `default-collision-filter-mode`)"


def test_table_is_markdown_with_a_row_per_statement():
    text = documented.table()
    lines = [line for line in text.splitlines() if line.startswith("| ") and not line.startswith("| #")]
    assert len(lines) == len(documented.STATEMENTS)
    assert all(line.count(" | ") == 5 for line in lines), "a cell leaks an unescaped '|'"
    assert "deviates (listed: `velocity-clamp-on-free-base`)" in text or not deviations.applies("velocity-clamp-on-free-base")


VANISHED = '''
from conformance.bullet.deviations import expected_failure

@expected_failure("default-collision-filter-mode", version="3.2.7")
def test_behaves_as_documented():
    pass

@expected_failure("default-collision-filter-mode", version="3.2.4")
def test_not_affected_runs_plainly():
    pass
'''


def test_a_listed_deviation_that_goes_away_fails_the_run(pytester):
    """Strict: a check marked with a deviation that behaves as documented is XPASS(strict), a failure
    that names the deviation, not a silent pass."""
    pytester.makepyfile(test_vanished=VANISHED)
    result = pytester.runpytest("-p", "no:cacheprovider", "-rX")
    result.assert_outcomes(failed=1, passed=1)
    result.stdout.fnmatch_lines(["*XPASS(strict)*default-collision-filter-mode*"])


def test_an_expected_failure_offers_no_patch_to_the_kit_s_own_files(tmp_path):
    """Issue 30, point 8: an all-pass run printed Hypothesis' "`git apply .hypothesis/patches/….patch` to
    add failing test cases to your code" for the draws of the xfailed deviations: a patch of the kit's
    installed files, not of the user's code."""
    import subprocess
    import sys

    from conformance.backends.display import child_environment

    run = subprocess.run([sys.executable, "-m", "pytest", "--pyargs", "conformance", "-p", "no:cacheprovider",
                          "-k", "test_default_filter_mode_is_and"], cwd=tmp_path, capture_output=True, text=True,
                         env=child_environment())
    assert run.returncode == 0 and "1 xfailed" in run.stdout, run.stdout[-2000:] + run.stderr[-2000:]
    assert "git apply" not in run.stdout and not (tmp_path / ".hypothesis" / "patches").exists(), run.stdout[-2000:]
