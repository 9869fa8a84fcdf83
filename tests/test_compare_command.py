"""``python -m conformance compare SPEC SPEC [SCENE…]``: two syncs side by side, which one pyBullet
agrees with, its exit status, and one clear paragraph for each thing that can go wrong."""

from __future__ import annotations

import re

import numpy as np
import pytest

import actor_data
from conformance import backends, cli
from conformance.implementations.reference import ReferenceSync


class RaisesAtFrame3(ReferenceSync):
    """Right until its fourth call (frame 3), which raises."""

    def __init__(self, world):
        super().__init__(world)
        self.calls = 0

    def __call__(self):
        self.calls += 1
        if self.calls == 4:
            raise ZeroDivisionError("division by zero on purpose")
        super().__call__()


class WritesNaNFromFrame2(ReferenceSync):
    """Right, except that from frame 2 on it writes NaN into the first vertex of the first target."""

    def __init__(self, world):
        super().__init__(world)
        self.world, self.calls = world, 0

    def __call__(self):
        super().__call__()
        self.calls += 1
        if self.calls >= 3:
            t = self.world.targets[0]
            actor_data.vertices(t.actor)[t.start] = np.nan
            actor_data.announce(t.actor)


def compare(capsys, *args):
    status = cli.main(["compare", *args])
    out, err = capsys.readouterr()
    return status, out, err


def test_reference_and_a_right_sync_both_agree(capsys):
    status, out, err = compare(capsys, "reference", "right_syncs:UserMatrixSync", "free_fall", "pendulum", "--frames", "30")
    assert status == 0, out + err
    assert out.count("pyBullet agrees with: both") == 2
    assert "free_fall, frames 0..30: A = 'reference', B = 'right_syncs:UserMatrixSync'\n  params {\"height\": 3.0, " in out
    assert "every target drawn alike" in out
    assert out.rstrip().endswith("both agree with pyBullet on every scene compared (2).")


def test_reference_and_a_wrong_sync_name_the_scene_target_and_frame(capsys):
    status, out, err = compare(capsys, "reference", "wrong_syncs:StaleLinkState", "chain", "free_fall", "--frames", "20")
    assert status == 1, out + err
    chain = out.split("\n\n")[0]
    assert chain.startswith("chain, frames 0..20: A = 'reference', B = 'wrong_syncs:StaleLinkState'")
    assert chain.splitlines()[2] == "  pyBullet agrees with: A"
    header, first = chain.splitlines()[3:5]
    assert header.split() == ["target", "largest", "A–B", "distance", "A's", "worst", "error", "B's", "worst", "error",
                              "vertices", "agree"]
    # One step late: each link drawn where it was a frame ago, millimetres off; the reference within tolerance.
    assert re.fullmatch(r"  link_\d+ +[\d.e-]+ m = [\d.e+]+×tol \(frame \d+\) +[\d.e-]+×tol \(frame \d+\) +"
                        r"[\d.e+]+×tol \(frame \d+\) +A", first), first
    assert "free_fall, frames 0..20" in out and "pyBullet agrees with: both" in out  # no links there: nothing late
    assert "A ('reference') agrees with pyBullet on every scene compared." in out
    assert re.search(r"B \('wrong_syncs:StaleLinkState'\) does not agree with pyBullet on 1 of 2 scenes: "
                     r"chain \([\d.e+]+×tol, 'link_\d+', frame \d+\)\.", out)


def test_the_same_spec_twice_is_allowed_and_said(capsys):
    status, out, _ = compare(capsys, "reference", "reference", "free_fall", "--frames", "3")
    assert status == 0
    assert out.startswith("note: A and B are the same implementation (conformance.implementations.reference:ReferenceSync)")


def test_a_sync_that_raises_mid_run_names_side_scene_and_frame(capsys):
    status, out, _ = compare(capsys, "reference", "test_compare_command:RaisesAtFrame3", "free_fall", "--frames", "10")
    assert status == 1
    assert ("B ('test_compare_command:RaisesAtFrame3') raised on scene 'free_fall' at frame 3, so the comparison stops "
            "there (frames 0..2 compared): sync implementation 'test_compare_command:RaisesAtFrame3' raised on scene "
            "'free_fall' at step 3: ZeroDivisionError: division by zero on purpose at ") in out
    assert "does not agree with pyBullet on 1 of 1 scenes: free_fall (raised at frame 3)." in out


def test_nan_written_is_named_with_its_first_frame(capsys):
    status, out, _ = compare(capsys, "test_compare_command:WritesNaNFromFrame2", "reference", "free_fall", "--frames", "5")
    assert status == 1
    assert "pyBullet agrees with: B" in out
    assert ("A ('test_compare_command:WritesNaNFromFrame2') wrote non-finite coordinates (NaN or inf) into the vertices "
            "of 1 target, first 'body' at frame 2: 'body' (body 0) is drawn at non-finite coordinates (nan, nan, nan)") in out
    assert "free_fall (non-finite, 'body', frame 2)" in out


def test_pictures_and_changes_the_renderer_was_not_told_of(capsys):
    status, out, _ = compare(capsys, "reference", "wrong_syncs:ForgetsModified", "brick_wall_single", "--frames", "5",
                             "--image")
    assert status == 1
    assert re.search(r"B \('wrong_syncs:ForgetsModified'\) changed vertex data without " + re.escape(backends.ANNOUNCE) +
                     r" in 5 sync calls \(first: actor 'bricks' at frame 1: its (points|positions) changed", out)
    assert re.search(r"pictures at frame 5: differ beyond the same-renderer tolerance: same-renderer: "
                     r"differing_fraction [\d.e-]+ > 0.00023 \(\d+ pixels differ", out)


@pytest.mark.parametrize("args, message", [
    (["reference", "reference", "no_such_scene"], "error: scene 'no_such_scene' is not a scene; the scenes are: ball_collision, "),
    (["reference", "no_such_module:Sync", "free_fall"], "error: sync implementation 'no_such_module:Sync': importing "
                                                        "module 'no_such_module' failed with ModuleNotFoundError"),
    (["reference", "right_syncs:NoSuchClass", "free_fall"], "error: sync implementation 'right_syncs:NoSuchClass': "
                                                            "module 'right_syncs' has no attribute 'NoSuchClass'"),
    (["reference", "reference", "free_fall", "--frames", "-1"], "error: --frames=-1 (int), but should be a whole number from 0"),
    (["reference", "reference", "free_fall", "--frames", "ten"], "error: --frames='ten' (str), but should be a whole number"),
    (["reference", "reference", "free_fall", "--image", "121"], "error: --image=121, but scene 'free_fall' runs frames "
                                                                "0..120 only"),
    (["reference", "reference", "free_fall", "--image", "-2"], "error: --image=-2 (int), but should be a whole number from 0"),
    (["reference", "reference", "--image", "free_fall"], "error: --image='free_fall' (str), but should be a frame number, 0 or "
                                                         "more; 'free_fall' is a scene: name the scenes before --image"),
    (["reference", "reference", "--params", '{"size": 1}'], "error: --params applies to one scene, but 17 are selected"),
    (["reference", "reference", "free_fall", "--params", '{"rows": 1}'], "error: --params names 'rows', but scene "
                                                                         "'free_fall' has no such parameter"),
])
def test_bad_input_is_one_paragraph_and_exit_2_before_anything_runs(capsys, args, message):
    status, out, err = compare(capsys, *args)
    assert status == 2
    assert out == "" and err.startswith(message) and err.count("\n") == 1, err


class ReadsClientZero(ReferenceSync):
    """Right, but it also reads every body's pose from pybullet without the scene's client (client 0)."""

    def __call__(self):
        import pybullet

        for t in self.targets:
            pybullet.getBasePositionAndOrientation(t.body)
        super().__call__()


def test_a_sync_reading_client_zero_does_not_agree_on_either_side(capsys):
    """``compare`` runs its scenes off pyBullet's default client as the checks do (``runner.running``
    holds client 0 with a decoy), on side A and on side B, so it never calls a sync right that
    the checks reject, and its paragraph says to use ``world.p``."""
    for args in (("test_compare_command:ReadsClientZero", "reference"), ("reference", "test_compare_command:ReadsClientZero")):
        status, out, _ = compare(capsys, *args, "free_fall", "--frames", "3")
        assert status == 1, out
        assert "GetBasePositionAndOrientation failed" in out
        assert "client 0, the default of every pybullet call made without physicsClientId" in out
        assert "p = world.p" in out
