"""Failures name the mistake when it is a known one (conformance.judge.diagnosis): every wrong sync in
``tests/`` whose mistake is in the catalogue gets its diagnosis, on both backends, at its first failing
frame; mistakes outside the catalogue get none; and the line reaches the checks' failure messages and
``check``'s output."""

from __future__ import annotations

import pytest

import wrong_syncs
from conformance import sync
from conformance.sync import runner
from conformance.judge import compare, diagnosis
from conformance.bullet import events
from right_syncs import PerTargetSync

STATIC_MOVED = [events.Teleport(frame=3, which=0, offset=(0.0, 0.0, 0.5), orientation=(0.0, 0.0, 0.3826834, 0.9238795))]


class RotationOnly(PerTargetSync):
    """Turns every body but leaves it where it was built."""

    def __call__(self):
        self.draw((t, t.position, self.link_pose(t)[1]) for t in self.targets)


class SwappedPoses(PerTargetSync):
    """Draws each body at the next body's pose (a list of poses zipped with the wrong list of targets)."""

    def __call__(self):
        found = [self.link_pose(t) for t in self.targets]
        self.draw((t, *found[(i + 1) % len(found)]) for i, t in enumerate(self.targets))


class NormalsInverse(wrong_syncs.Baseline):
    """Moves shared actors' vertices right but turns their stored normals by the inverse rotation."""

    def place_shared(self, t, pos, orn):
        rotation = self.matrix(orn)
        self.vertex_view(t.actor)[t.start:t.stop] = self.local[t.name] @ rotation.T + pos
        if t.name in self.local_normals:
            self.normal_view(t.actor)[t.start:t.stop] = self.local_normals[t.name] @ rotation


class NormalsTwice(wrong_syncs.Baseline):
    """Moves shared actors' vertices right but turns their stored normals twice."""

    def place_shared(self, t, pos, orn):
        rotation = self.matrix(orn)
        self.vertex_view(t.actor)[t.start:t.stop] = self.local[t.name] @ rotation.T + pos
        if t.name in self.local_normals:
            self.normal_view(t.actor)[t.start:t.stop] = self.local_normals[t.name] @ (rotation @ rotation).T


class NormalsHalfTurned(wrong_syncs.Baseline):
    """Moves shared actors' vertices right but turns their stored normals by half the body's rotation."""

    def place_shared(self, t, pos, orn):
        from scipy.spatial.transform import Rotation, Slerp

        self.vertex_view(t.actor)[t.start:t.stop] = self.local[t.name] @ self.matrix(orn).T + pos
        if t.name in self.local_normals:
            half = Slerp([0, 1], Rotation.from_quat([t.orientation, orn]))(0.5).as_matrix()
            self.normal_view(t.actor)[t.start:t.stop] = self.local_normals[t.name] @ half.T


class NormalsOneStepLate(wrong_syncs.Baseline):
    """Moves shared actors' vertices right but turns their stored normals by the previous call's rotation."""

    def place_shared(self, t, pos, orn):
        late = getattr(self, "_late", {})
        self._late = late
        self.vertex_view(t.actor)[t.start:t.stop] = self.local[t.name] @ self.matrix(orn).T + pos
        if t.name in self.local_normals:
            rotation = self.matrix(late.get(t.name, orn))
            self.normal_view(t.actor)[t.start:t.stop] = self.local_normals[t.name] @ rotation.T
        late[t.name] = orn


def _implementation(spec):
    if isinstance(spec, str):
        return sync.load(spec)
    return sync.SyncImplementation(spec=spec.__name__, target=f"tests:{spec.__name__}", factory=spec)


def first_diagnosis(spec, scene: str, frames: int, run_events=(), **params):
    """The frame of the first failing vertex check and the mistake its diagnosis names (or None)."""
    with runner.running(scene, _implementation(spec), events=run_events, **params) as run:
        for frame in range(frames + 1):
            if frame:
                run.advance()
            results = compare.compare_vertices(run.drawing, frame)
            if not all(r.ok for r in results):
                found = diagnosis.explain_frame(run, results)
                return frame, found[0] if found else None
    raise AssertionError(f"{spec} drew {scene} right for {frames} frames: no failure to diagnose")


@pytest.mark.parametrize("spec, scene, run_events, mistake", [
    ("wrong_syncs:OneStepLate", "free_fall", (), "previous-step"),
    ("wrong_syncs:StaleLinkState", "pendulum", (), "previous-step"),
    ("wrong_syncs:TransposedRotation", "free_fall", (), "conjugate"),
    ("wrong_syncs:ConjugateQuaternion", "tumbling", (), "conjugate"),
    ("wrong_syncs:QuaternionWXYZ", "free_fall", (), "scalar-first"),
    ("wrong_syncs:LinkCOMFrame", "pendulum", (), "com-frame"),
    ("wrong_syncs:IgnoresBaseInertialFrame", "weighted", (), "com-frame"),
    ("wrong_syncs:EulerRotateXYZ", "free_fall", (), "euler-order"),
    ("wrong_syncs:DoesNothing", "free_fall", (), "never-moved"),
    ("wrong_syncs:SkipsLastTarget", "crossing", (), "never-moved"),
    ("wrong_syncs:VelocityGated", "sliding_box", STATIC_MOVED, "before-event"),
    ("wrong_syncs:StaticPlacedOnce", "sliding_box", STATIC_MOVED, "before-event"),
    (RotationOnly, "free_fall", (), "rotation-only"),
    (SwappedPoses, "crossing", (), "other-target"),
    ("wrong_syncs:FirstMultibodyOnly", "pendulum", (), "other-target"),
], ids=lambda v: getattr(v, "__name__", None) or (v.split(":")[-1] if isinstance(v, str) else None))
def test_a_mistake_in_the_catalogue_gets_its_diagnosis(spec, scene, run_events, mistake):
    # pendulum: three double pendulums, whose links share indices (the scene's own example).
    params = {"pendulums": 3, "links": 2} if scene == "pendulum" and spec == "wrong_syncs:FirstMultibodyOnly" else {}
    assert first_diagnosis(spec, scene, 30, run_events, **params)[1] == mistake


@pytest.mark.parametrize("spec, scene", [
    ("wrong_syncs:InflatedAgainstZFighting", "free_fall"),   # drawn 0.1 % too large: no pose draws that
    ("wrong_syncs:CentreNotUpdated", "brick_wall_single"),   # turned about a stale centre
    ("wrong_syncs:WrongVertexRange", "wrecking_ball"),       # ranges shifted across links
    ("wrong_syncs:Float32Incremental", "tumbling"),          # rounding that builds up
])
def test_a_mistake_outside_the_catalogue_gets_no_diagnosis(spec, scene):
    frames = 3000 if scene == "tumbling" else 131
    assert first_diagnosis(spec, scene, frames)[1] is None


def first_problem_diagnosis(spec, scene: str, frames: int, **params) -> tuple[int, str]:
    """The frame of the first problem of any kind ``check`` reports, and its diagnosis line."""
    from conformance.rendering.animation import check_frame

    with runner.running(scene, _implementation(spec), **params) as run:
        for frame in range(frames + 1):
            if frame:
                run.advance()
            if not check_frame(run, frame).ok:
                return frame, diagnosis.diagnose_problems(run)
    raise AssertionError(f"{spec} drew {scene} right for {frames} frames: no failure to diagnose")


@pytest.mark.parametrize("spec, words", [
    ("wrong_syncs:NormalsNotRotated", "as built"),
    (NormalsOneStepLate, "step late"),
    (NormalsInverse, "inverse rotation"),
    (NormalsTwice, "turned twice"),
    ("wrong_syncs:ForgetsModified", "never announced"),
], ids=lambda v: getattr(v, "__name__", None) or (v.split(":")[-1] if isinstance(v, str) else None))
def test_right_vertices_with_a_known_mistake_in_normals_or_announcements_get_its_diagnosis(spec, words):
    # Shared sphere actors (mixed_shapes by kind) store normals; every body turns from the first step.
    frame, line = first_problem_diagnosis(spec, "mixed_shapes", 30, grouping="by_kind")
    assert line.startswith("diagnosis: ") and words in line, (frame, line)


def test_normals_a_step_late_are_told_from_stale_ones_once_the_body_has_turned():
    # At frame 1 the previous rotation is the built one (both mistakes fit, and the line says so);
    # from frame 2 on each mistake is named alone.
    for spec, mistake in (("wrong_syncs:NormalsNotRotated", "stale-normals"), (NormalsOneStepLate, "normals-previous-step")):
        with runner.running("mixed_shapes", _implementation(spec), grouping="by_kind") as run:
            run.advance(5)
            turned = [r for r in compare.compare_normals(run.drawing, run.frame) if not r.ok]
            assert diagnosis.explain_normals(run, max(turned, key=lambda r: r.angle))[0] == mistake


def test_wrong_normals_outside_the_catalogue_get_no_diagnosis():
    # Normals turned by half the body's rotation since it was built: halfway between "as built" and
    # right, which no catalogued rotation gives.
    frame, line = first_problem_diagnosis(NormalsHalfTurned, "mixed_shapes", 60, grouping="by_kind")
    assert line == "", (frame, line)


def test_the_diagnosis_is_under_the_failure_of_a_check_and_of_check(capsys):
    from conformance.commands import check
    from conformance.checks.pytest_helpers import assert_vertices_match

    with runner.running("free_fall", sync.load("wrong_syncs:OneStepLate")) as run:
        run.advance(5)
        with pytest.raises(pytest.fail.Exception) as failed:
            assert_vertices_match(compare.compare_vertices(run.drawing, run.frame), run=run, sync="wrong_syncs:OneStepLate")
    lines = str(failed.value).splitlines()
    assert lines[1].startswith("diagnosis: drawn exactly at pyBullet's pose of the previous step (frame 4)")
    assert lines[-1].startswith("reproduce: ")

    class Args:
        scene, sync_given, frames, params, events, verbose = "free_fall", "wrong_syncs:OneStepLate", "5", None, None, False

    assert check.run(Args(), []) == 1
    out = capsys.readouterr().out.splitlines()
    assert out[-1].startswith("diagnosis: drawn exactly at pyBullet's pose of the previous step (frame 0)")


def test_the_json_report_carries_the_diagnosis(pytester, monkeypatch):
    from pathlib import Path
    import json

    monkeypatch.setenv("PYTHONPATH", str(Path(__file__).parent))
    report = pytester.path / "report.json"
    result = pytester.runpytest_subprocess("--pyargs", "conformance", "-p", "no:cacheprovider", "-k",
                                           "test_pass_through_is_drawn_overlapping", "--sync", "wrong_syncs:OneStepLate",
                                           "--conformance-report", str(report),
                                           # Hypothesis picks its "ci" profile itself where $CI is set: shrinking
                                           # this wrong sync's counter-examples took 82 s of CI for nothing here.
                                           "--hypothesis-profile", "default")
    result.assert_outcomes(failed=1)
    failed = [r for r in json.loads(report.read_text())["records"] if r.get("outcome") == "failed"]
    assert failed and all(r["diagnosis"].startswith("drawn exactly at pyBullet's pose of the previous step")
                          for r in failed), failed
