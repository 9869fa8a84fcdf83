"""The zoo (issue 47): right programs of pybullet_data's models, in the styles users write, accepted; the same
programs with one mistake each rejected.

Every CI run judges a slice of the zoo seeded by the commit (as ``test_random_draws`` does for random draws:
``KIT_DRAW_SEED=N`` replays one), so that over commits the slices cover the population; ``python -m
conformance zoo`` judges all of it (docs/zoo.md). The other tests show the zoo's own parts doing what they
say: every style and mistake writes a program, the survey names what it cannot judge, and the zoo's verdicts
fail when app mode rejects a right program or misses a wrong one.
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import pytest

import background
import confusion_records
from conformance import backends
from conformance.apps.verdict import lead
from conformance.discrimination import precision
from conformance.zoo import judging, mistakes, models, programs, styles

ROOT = Path(__file__).resolve().parent.parent
SEED, SOURCE = precision.draw_seed(ROOT)
#: right programs, and as many wrong ones, of each CI run's slice
SLICE = 3


def _slice():
    def call():
        with tempfile.TemporaryDirectory(prefix="kit-zoo-") as tmp:
            done = subprocess.run([sys.executable, "-m", "conformance", "zoo", "--sample", str(SLICE), "--seed", str(SEED),
                                   "--mistakes", "all", "--results", tmp], capture_output=True, text=True, timeout=1200)
            return done, judging.load_journal(sorted(Path(tmp).glob("journal/*.jsonl")))
    return f"zoo:{SEED}", call


def background_runs(items) -> dict:
    if not any(item.name == "test_a_slice_of_the_zoo_seeded_by_the_commit" for item in items):
        return {}
    key, call = _slice()
    return {key: (2, call)}


def test_a_slice_of_the_zoo_seeded_by_the_commit():
    """Right programs drawn from the zoo with the commit's seed pass app mode; wrong ones (a mistake of
    :mod:`conformance.zoo.mistakes` each) fail it, or change nothing the model shows."""
    done, outcomes = background.result(*_slice())
    replay = f"python -m conformance zoo --sample {SLICE} --seed {SEED} --mistakes all  # in {backends.NAME}'s environment"
    assert done.returncode in (0, 1) and outcomes, f"the zoo did not run ({SOURCE}): {done.stderr[-1500:]}"
    bad = [o for o in outcomes if o.outcome in (("missed", "error") if o.mistake else ("rejected", "error"))]
    assert not bad, (f"the zoo's slice of seed {SEED} ({SOURCE}) failed: " + "; ".join(
        f"{o.model} {o.style}{' with ' + o.mistake if o.mistake else ''}: {o.outcome}: {o.first}" for o in bad)
        + f". Replay: `{replay}`")
    assert done.returncode == 0, done.stdout[-1500:]
    assert sum(not o.mistake for o in outcomes) >= 1 and sum(bool(o.mistake) for o in outcomes) >= 1, outcomes
    for o in outcomes:  # issue 48: the mistake each rejection leads with, held to the committed confusion record
        if o.mistake and o.outcome == "rejected":
            confusion_records.assert_named_no_worse("zoo", f"{o.model} {o.style} {o.mistake}", actual=lead(o.diagnoses),
                                                    expected=mistakes.MISTAKES[o.mistake].diagnosis or "-",
                                                    where=f"{o.first}; replay: {replay}")


@pytest.mark.fury_free("program text only: no FURY is run")
@pytest.mark.parametrize("model", ["r2d2.urdf", "mjcf/capsule.xml", "kuka_iiwa/kuka_with_gripper.sdf"])
def test_every_style_and_mistake_writes_a_program(model):
    """Each style on each FURY it is for, right and with each mistake that applies to it, is a Python program,
    and the mistake changes it (an edit that found nothing would leave a right program labelled wrong)."""
    for style in styles.STYLES.values():
        for backend in style.backends:
            right = programs.program(models.Model(model), style, backend)
            compile(right, f"{model}-{style.name}", "exec")
            assert "EXPECT: pass" in right
            for mistake in mistakes.MISTAKES.values():
                if mistake.applies(style):
                    wrong = programs.program(models.Model(model), style, backend, mistake.name)
                    compile(wrong, f"{model}-{style.name}-{mistake.name}", "exec")
                    assert "EXPECT: fail" in wrong and wrong.replace("EXPECT: fail", "") != right


@pytest.mark.fury_free("pyBullet alone")
def test_the_survey_says_why_a_model_is_not_judged():
    found = models.survey([models.Model("plane.urdf"), models.Model("gripper/wsg50_one_motor_gripper_free_base.sdf"),
                           models.Model("r2d2.urdf"), models.Model("mjcf/cylinder_fromtoX.xml"),
                           models.Model("mjcf/cylinder_fromtoZ.xml")])
    assert found["plane.urdf"].unusable.startswith("nothing moves")
    # pyBullet's visual frame of an MJCF fromto cylinder along x is the identity (along z), its collision box along x
    assert found["mjcf/cylinder_fromtoX.xml"].unusable.startswith("getVisualShapeData gives body"), found["mjcf/cylinder_fromtoX.xml"]
    assert not found["mjcf/cylinder_fromtoZ.xml"].unusable  # along z, the identity is right
    assert found["gripper/wsg50_one_motor_gripper_free_base.sdf"].unusable.startswith("pyBullet crashes loading it")
    r2d2 = found["r2d2.urdf"]
    assert not r2d2.unusable and r2d2.movable and r2d2.fixed_joints and r2d2.spheres, r2d2


def test_a_right_program_app_mode_rejects_fails_the_zoo(tmp_path):
    """The zoo's verdict on a right program is app mode's: a program that draws one step late, judged as if
    right, is "rejected" (``test_zoo`` fails on it), with app mode's first line and diagnosis."""
    model, style = models.Model("cube_small.urdf"), styles.STYLES["links"]
    path = judging.write_program(model, style, backends.NAME, tmp_path, "one-step-late")
    outcome = judging.judge_program(path, model, style, backends.NAME, ticks=20, perturbed=0)
    assert outcome.outcome == "rejected" and "previous-step" in outcome.diagnoses, outcome


def test_a_wrong_program_is_held_against_the_right_ones_drawing(tmp_path, monkeypatch):
    """A wrong program app mode accepts is a miss only if its drawing differs from the right program's: the
    centre of mass drawn for a cube whose inertial origin is its centre changes nothing ("no-difference");
    a step late, accepted (app mode made to accept everything here), is "missed"."""
    def accepted(path, model, style, backend, **kwargs):
        return judging.Outcome(model.path, style.name, backend, "accepted")

    monkeypatch.setattr(judging, "judge_program", accepted)
    model, style = models.Model("cube_small.urdf"), styles.STYLES["links"]
    right = judging.write_program(model, style, backends.NAME, tmp_path)
    for mistake, expected in (("com-frame", "no-difference"), ("one-step-late", "missed")):
        wrong = judging.write_program(model, style, backends.NAME, tmp_path, mistake)
        outcome = judging.judge_wrong(wrong, right, model, style, backends.NAME, mistake, ticks=20)
        assert outcome.outcome == expected, (mistake, outcome)
        assert (outcome.shown > judging.SAME) == (expected == "missed"), outcome


@pytest.mark.fury_free("the table from outcomes made by hand")
def test_the_table_tells_whether_each_rejection_names_its_mistake():
    """Issue 48's measure on the zoo: a rejection whose report leads with its mistake's diagnosis (the most
    explanatory named, whatever the order kept) is named first, one that has it after another is named later,
    one with none is silent, and one that leads with another is named wrong and counted under the name it got;
    a right program's rejection is no part of it."""
    from conformance.zoo import table

    made = [judging.Outcome("m.urdf", "links", "vtk", "rejected", "one-step-late", diagnoses=["never-moved", "previous-step"]),
            judging.Outcome("n.urdf", "links", "vtk", "rejected", "one-step-late", diagnoses=["previous-step", "skipped"]),
            judging.Outcome("o.urdf", "links", "vtk", "rejected", "one-step-late", diagnoses=[]),
            judging.Outcome("p.urdf", "links", "pygfx", "rejected", "one-step-late", diagnoses=["skipped"]),
            judging.Outcome("p.urdf", "links", "pygfx", "rejected", "", diagnoses=["skipped"])]
    page = table.markdown(made, {}, made_by="hand")
    assert "| one-step-late | `previous-step` | 4 | 1 | 1 | 1 | 1 (skipped 1) |" in page, page
    assert "Named first: 1 of 4 (25 %); named wrong (another first): 1; none: 1." in page, page


@pytest.mark.fury_free("arrays only")
def test_the_oracle_sees_what_is_drawn_not_how_its_vertices_are_numbered():
    """A box turned a half turn about x (a cart drawn with a reordered identity quaternion) puts every corner
    where another was: the same surface, 0 m apart as drawn, though each vertex moved; a box moved 1 cm is 1 cm
    apart either way."""
    corners = np.array([[x, y, z] for x in (-0.25, 0.25) for y in (-0.25, 0.25) for z in (-0.1, 0.1)])
    right = np.broadcast_to(corners, (3, 8, 3))
    turned = right * [1.0, -1.0, -1.0]
    assert np.max(np.linalg.norm(turned - right, axis=-1)) > 0.5
    assert judging._apart(turned, right) == 0.0
    assert judging._apart(right + [0.01, 0.0, 0.0], right) == pytest.approx(0.01)
