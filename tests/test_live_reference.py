"""A golden's two picture verdicts, each failing on its own deliberately wrong input.

The sync verdict judges the sync's render against a live reference (the ``reference`` sync drawing
the same restored state on this renderer, same-renderer set); the renderer verdict judges that live
reference against the stored golden (:mod:`conformance.rendering.reftest`). Here: a sync that draws
wrong fails the first and not the second; a golden made "elsewhere" fails the second and not the
first; a renderer's name no longer picks the looser set where the pictures agree; a run says both
verdicts apart in the terminal, the JSON and report.html; and on the other renderers reachable here
(softpipe and zink, FURY 0.12), run in child processes, the reference passes and a wrong sync fails
the sync verdict alone.
"""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import pytest

from children import environment, run as run_child, said
from conformance import backends, scenes, sync
from conformance.sync import runner
from conformance.rendering import golden, measure_reftest, measure_tolerances, reftest, snapshots

TESTS = Path(__file__).resolve().parent
SCENE = "free_fall"
FRAMES = scenes.get(SCENE).frames_with_goldens()
ELSEWHERE = {"backend": backends.NAME, "renderer": "a GPU this machine does not have"}


@pytest.fixture(autouse=True)
def _wrong_syncs_importable(monkeypatch):
    monkeypatch.syspath_prepend(str(TESTS))


def _goldens(directory=None, scene=SCENE):
    with scenes.build(scene) as built:
        return {f: snapshots.load(directory or golden.default_dir(), built, f) for f in scenes.get(scene).frames_with_goldens()}


def verdicts(spec: str, scene: str = SCENE, directory=None, override=None):
    """Each golden frame's record, as test_golden_render makes it: the sync's renders first, the live references after."""
    goldens = _goldens(directory, scene)
    with runner.running(scene, sync.load(spec)) as run:
        drawn = {f: snapshots.draw(run, g) for f, g in goldens.items()}
    references = reftest.references(scene, goldens)
    return [reftest.judge(g, drawn[f], references[f], here=backends.renderer_info(), override=override, sync=spec)[0]
            for f, g in goldens.items()]


def _passed(record, name):
    return record.details["verdicts"][name]["passed"]


@pytest.mark.parametrize("spec, scene", [("wrong_syncs:TintsMovingBodies", "brick_wall_single"),
                                         ("wrong_syncs:OneStepLate", SCENE)])
def test_a_sync_that_draws_wrong_fails_the_sync_verdict_and_not_the_renderer_verdict(spec, scene):
    records = verdicts(spec, scene)
    assert any(not _passed(r, "sync") for r in records), [r.message for r in records]
    assert all(_passed(r, "renderer") for r in records), [r.message for r in records]
    failed = next(r for r in records if not r.passed)
    assert failed.message.startswith("sync verdict FAIL: the sync's render vs the live reference")
    assert "px differ, 39 allowed" in failed.message and "renderer verdict pass" in failed.message


def test_the_reference_passes_both_verdicts_and_its_live_reference_is_the_golden():
    for record in verdicts("reference"):
        assert record.passed, record.message
        assert record.metrics["sync: differing_pixels"] == 0 and record.metrics["renderer: differing_pixels"] == 0
        assert record.details["verdicts"]["renderer"]["why"] == "the golden's manifest names this renderer"


def test_a_body_moved_2_px_or_turned_3_degrees_in_the_picture_plane_fails_the_sync_verdict_at_every_frame():
    """What the other-renderer set cannot promise (docs/image-tolerances.md), the live reference does."""
    rows = measure_reftest.measure_scene(SCENE)
    assert [r["frame"] for r in rows] == list(FRAMES)
    for row in rows:
        assert row["reference_sync"]["passed"] and row["renderer"]["passed"], row
        for kind in measure_reftest.ERRORS:
            assert not row[kind]["passed"] and row[kind]["same"] > 4 * 39, (kind, row)


# -- a golden made elsewhere ---------------------------------------------------------------------------

def _remade(directory: Path, frame: int, *, renderer=None, change=None) -> None:
    """Rewrite ``directory``'s golden of SCENE at ``frame``: its manifest naming ``renderer``, its
    picture the reference's render of the stored state with ``change`` (``moved``: one body 2 px
    across; ``msaa_off``: no multisampling, as another renderer's anti-aliasing)."""
    stored = _goldens(directory)[frame]
    image = stored.image
    if change is not None:
        with runner.running(SCENE, sync.load("reference")) as run:
            snapshots.draw(run, stored)
            size = run.scene.image_size
            if change == "msaa_off":
                image = backends.render(run.drawing, run.scene.camera, size, multisamples=0)
            else:
                with measure_tolerances.perturbed(run, measure_tolerances.pick_target(run, size), change):
                    image = backends.render(run.drawing, run.scene.camera, size)
    golden.write(directory, SCENE, frame, image, {**stored.manifest, "renderer": renderer or stored.renderer})


@pytest.fixture
def copy(tmp_path):
    shutil.copytree(golden.default_dir() / SCENE, tmp_path / "goldens" / SCENE)
    return tmp_path / "goldens"


def test_a_golden_of_another_name_whose_pictures_agree_is_judged_with_the_same_renderer_set(copy):
    """The name misleads (zink draws llvmpipe's goldens to 0 pixels): the pictures decide."""
    for frame in FRAMES:
        _remade(copy, frame, renderer=ELSEWHERE)
    for record in verdicts("reference", directory=copy):
        renderer = record.details["verdicts"]["renderer"]
        assert record.passed and renderer["tolerance_set"] == "same-renderer", record.message
        assert "names another renderer, but the live reference equals the golden" in renderer["why"]


def test_a_golden_made_elsewhere_with_a_body_moved_fails_the_renderer_verdict_and_not_the_sync_verdict(copy):
    _remade(copy, FRAMES[1], renderer=ELSEWHERE, change="moved")
    records = {r.frame: r for r in verdicts("reference", directory=copy)}
    wrong = records[FRAMES[1]]
    assert _passed(wrong, "sync") and not _passed(wrong, "renderer"), wrong.message
    assert wrong.details["verdicts"]["renderer"]["tolerance_set"] == "other-renderer"
    assert all(records[f].passed for f in FRAMES if f != FRAMES[1])


def test_a_changed_stack_under_the_same_name_fails_the_renderer_verdict_tightly(copy):
    """Multisampling off is what another renderer may do, so the other-renderer set passes it; under
    this renderer's own name it is a change of the rendering stack, and the golden catches it."""
    _remade(copy, FRAMES[0], change="msaa_off")
    tight = next(r for r in verdicts("reference", directory=copy) if r.frame == FRAMES[0])
    assert _passed(tight, "sync") and not _passed(tight, "renderer"), tight.message
    _remade(copy, FRAMES[0], renderer=ELSEWHERE)  # the same picture, another renderer's name
    loose = next(r for r in verdicts("reference", directory=copy) if r.frame == FRAMES[0])
    assert loose.passed and loose.details["verdicts"]["renderer"]["tolerance_set"] == "other-renderer", loose.message


def test_an_asked_for_set_holds_both_verdicts():
    for record in verdicts("reference", override="other-renderer"):
        assert {v["tolerance_set"] for v in record.details["verdicts"].values()} == {"other-renderer"}
        assert record.details["tolerance_set"] == "other-renderer"


def test_a_run_reports_both_verdicts_apart_in_the_terminal_the_json_and_the_page(copy, tmp_path):
    _remade(copy, FRAMES[1], renderer=ELSEWHERE, change="moved")
    results = tmp_path / "results"
    done = run_child(["-m", "pytest", "--pyargs", "conformance", "-p", "no:cacheprovider", "-q", "-k",
                      f"test_golden_render and {SCENE}", "--conformance-golden-dir", str(copy),
                      "--conformance-results", str(results), "--conformance-report", str(tmp_path / "r.json")], tmp_path)
    assert done.returncode == 1, said(done)
    failure = [line for line in done.stdout.splitlines() if f"[{SCENE}, frame {FRAMES[1]}, sync 'reference']" in line]
    assert failure[0].startswith("renderer verdict FAIL: the live reference vs the stored golden"), said(done)
    assert failure[1].startswith("sync verdict pass"), said(done)
    assert "sync verdict (against a live reference render) 0 failed; renderer verdict (live reference against the golden) 1 failed" in done.stdout
    record = next(r for r in json.loads((tmp_path / "r.json").read_text())["records"] if r["check"] == "test_golden_render")
    by_frame = {v["frame"]: v for v in record["golden_verdicts"]}
    assert sorted(by_frame) == list(FRAMES)
    assert by_frame[FRAMES[1]]["sync"]["passed"] and not by_frame[FRAMES[1]]["renderer"]["passed"]
    page = (results / "report.html").read_text(encoding="utf-8")
    assert "renderer verdict: fail (other-renderer)" in page and "sync verdict: pass (same-renderer)" in page
    assert "live reference (reference sync, this renderer)" in page and "renderer verdict: live reference vs golden" in page


# -- other renderers, each in a child process --------------------------------------------------------

OTHER_RENDERERS = {
    "softpipe": ({"LIBGL_ALWAYS_SOFTWARE": "1", "GALLIUM_DRIVER": "softpipe"}, "other-renderer"),
    # zink draws llvmpipe's goldens to 0 pixels: the pictures choose the same-renderer set.
    "zink": ({"LIBGL_ALWAYS_SOFTWARE": "1", "GALLIUM_DRIVER": "zink", "XDG_RUNTIME_DIR": None}, "same-renderer"),
}


@pytest.mark.skipif(backends.NAME != "vtk", reason="softpipe and zink are OpenGL drivers: FURY 0.12 only")
@pytest.mark.parametrize("name", OTHER_RENDERERS)
@pytest.mark.full("whole runs on Mesa's other OpenGL drivers: the renderer's portability, not discrimination")
def test_on_another_renderer_the_reference_passes_and_a_wrong_sync_fails_the_sync_verdict_alone(tmp_path, name):
    variables, chosen = OTHER_RENDERERS[name]
    variables = {k: v if v is not None else str(tmp_path) for k, v in variables.items()}

    path = os.pathsep.join([str(TESTS), environment()["PYTHONPATH"]])  # the wrong syncs, and this checkout's kit

    def check(spec):
        return run_child(["-m", "pytest", "--pyargs", "conformance", "-p", "no:cacheprovider", "-q", "-k",
                          "test_golden_render and brick_wall_single", "--sync", spec,
                          "--conformance-results", str(tmp_path / spec.replace(":", "-"))],
                         tmp_path, PYTHONPATH=path, **variables)

    right = check("reference")
    assert right.returncode == 0, said(right)
    assert f"renderer verdict (live reference against the golden) 0 failed, judged with {chosen} 3" in right.stdout, said(right)
    wrong = check("wrong_syncs:TintsMovingBodies")
    assert wrong.returncode == 1, said(wrong)
    assert "sync verdict FAIL" in wrong.stdout and "renderer verdict FAIL" not in wrong.stdout, said(wrong)
