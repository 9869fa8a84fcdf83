"""A sync written before soft bodies (issue 49, point 1): it hands every target to its pose code, as the protocol
allowed before ``Target.nodes``, so it draws the ``cloth`` and ``soft_ball`` scenes' soft bodies as rigid ones.
On a soft scene its failures say so first, naming the soft body, ``Target.nodes``, the README and the way out;
and a program without soft bodies leaves soft scenes out with ``-m "not soft"`` (every check of a soft scene
carries the ``soft`` mark), on the command line or in the ini's ``addopts``, with every other check run and the
per-scene table naming the scenes left out and why.

The syncs are ``tests/rigid_only_syncs.py``: right syncs of the kit's, handed targets that say nothing of nodes."""

from __future__ import annotations

import json
import os
import re
from pathlib import Path

import pytest

from conformance import sync
from conformance import test_vertices as checks
from conformance.checks.pytest_helpers import Kit
from conformance.judge import diagnosis
from conformance.judge.tolerances import DEFAULT

TESTS = str(Path(__file__).resolve().parent)
BEFORE = "rigid_only_syncs:PosesEveryTarget"
#: What the diagnosis of a soft body drawn as a rigid one must say: the body, that it is soft, what to copy,
#: where the README says so, and how a program without soft bodies leaves soft scenes out.
TOLD = [r"is a soft body \(Target\.nodes is not None\)", re.escape("p.getMeshData(body, -1, flags=p.MESH_DATA_SIMULATION_MESH)[1]"),
        re.escape("(README, The sync protocol)"), re.escape('-m "not soft" leaves soft scenes out')]


@pytest.fixture
def kit_run(pytester, monkeypatch):
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join(filter(None, [TESTS, os.environ.get("PYTHONPATH")])))

    def run(*args):
        result = pytester.runpytest_subprocess("--pyargs", "conformance", "-p", "no:cacheprovider", "--sync", BEFORE,
                                               "--conformance-report", "report.json", *args)
        text = result.stdout.str()
        rows = {m.group(2): (m.group(1), m.group(3)) for m in
                re.finditer(r"^(PASS|FAIL|SKIP|INCOMPLETE|NOT RUN|LEFT OUT) +(\w+) +(.*)$", text, re.M)}
        report = pytester.path / "report.json"
        records = json.loads(report.read_text())["records"] if report.is_file() else []
        return result, rows, records, text
    return run


def test_a_sync_written_before_soft_bodies_is_told_so_on_a_soft_scene(kit_run):
    """Every vertex and picture check it fails on the cloth leads with the soft body's diagnosis."""
    result, rows, records, text = kit_run("-k", "cloth and (test_vertices_match_poses_every_frame or test_golden_render "
                                                "or test_silhouettes_match_pybullet_at_golden_frames)")
    assert result.ret == pytest.ExitCode.TESTS_FAILED, text
    failed = {r["check"]: r for r in records if r["outcome"] == "failed"}
    assert set(failed) == {"test_vertices_match_poses_every_frame", "test_golden_render",
                           "test_silhouettes_match_pybullet_at_golden_frames"}, text
    for record in failed.values():
        assert record["diagnosis"].startswith("'cloth' is a soft body"), (record["check"], record["diagnosis"])
        assert all(re.search(words, record["diagnosis"]) for words in TOLD), (record["check"], record["diagnosis"])
    # In the terminal, right under each failure's first line (the golden render's: its first failing verdict).
    # Counted above the short summary, which repeats whole messages when CI is set (pytest does not truncate there).
    failures = text.split("short test summary info")[0]
    assert len(re.findall(r"\]\ndiagnosis: 'cloth' is a soft body", failures)) == 3, text
    assert rows["cloth"][0] == "FAIL", text


def test_the_same_sync_with_soft_scenes_left_out_passes_every_check_it_runs(kit_run):
    # free_fall stands for the rigid scenes; its determinism across processes (pyBullet's, 4 s of processes) is left out
    result, rows, records, text = kit_run("-m", "not soft", "-k", "(cloth or soft_ball or free_fall) and not across_processes")
    assert result.ret == pytest.ExitCode.OK, text
    assert records and all(r["outcome"] == "passed" for r in records), text
    assert {r["scene"] for r in records} == {"free_fall", None}, text  # None: test_materials' free-fall law (pyBullet alone)
    assert rows["free_fall"][0] == "PASS" and "18 passed; 1 of its checks not selected" in rows["free_fall"][1], text
    for scene in ("cloth", "soft_ball"):
        assert rows[scene][0] == "LEFT OUT", text
        assert rows[scene][1].startswith("left out: -m 'not soft' deselected 18 of its 19 checks, -k '(cloth or soft_ball "
                                         "or free_fall) and not across_processes' the other 1") and "soft bodies" in rows[scene][1], text
    assert set(rows) == {"free_fall", "cloth", "soft_ball"}, text  # the scenes -k left out are not listed


def test_an_ini_that_leaves_soft_scenes_out_is_said_in_the_table(kit_run, pytester):
    """``addopts = -m "not soft"``: the soft scenes' checks are not run, and the table says which and why."""
    pytester.makeini('[pytest]\naddopts = -m "not soft"\n')
    result, rows, records, text = kit_run("-k", "cloth or soft_ball")
    assert result.ret == pytest.ExitCode.NO_TESTS_COLLECTED, text  # every selected check was a soft scene's
    assert not records, text
    assert {scene: verdict for scene, (verdict, _) in rows.items()} == {"cloth": "LEFT OUT", "soft_ball": "LEFT OUT"}, text
    assert all(detail.startswith("left out: -m 'not soft'") for _, detail in rows.values()), text


def _kit(spec: str) -> Kit:
    return Kit(sync.load(spec), DEFAULT)


@pytest.mark.parametrize("spec, how, frame", [
    (BEFORE, "posed it as if rigid", 0),                                  # its actor's transform set, vertices as built
    ("rigid_only_syncs:rewrites_every_target", "posed it as if rigid", 0),  # its vertices rewritten at a rigid pose
    ("rigid_only_syncs:LeavesSoftBodiesAlone", "never wrote its vertices", 1),  # right at frame 0, then left behind
], ids=["transform", "vertices", "left-alone"])
def test_each_way_of_drawing_a_soft_body_as_rigid_is_named(spec, how, frame):
    with pytest.raises(pytest.fail.Exception, match=rf"'ball' \(body \d\) vertex \d+ is drawn at .*frame {frame}, .*\n"
                                                    rf"diagnosis: 'ball' is a soft body \(Target.nodes is not None\) and "
                                                    rf"the sync {how}: .*-m \"not soft\""):
        checks.test_vertices_match_poses_every_frame("soft_ball", _kit(spec))


@pytest.mark.parametrize("spec", ["reference", "soft_syncs:OneStepLateNodes", "soft_syncs:CopiedOnce",
                                  "soft_syncs:NodesReversed"])
def test_a_sync_that_copies_nodes_is_never_told_it_drew_a_soft_body_as_rigid(spec):
    """The right sync, and the wrong ones that copy nodes (late, once, in another order): no such diagnosis at
    any frame, on a cloth that sags from the first step and a ball that falls as one piece before it lands."""
    from conformance.sync import runner

    for scene in ("cloth", "soft_ball"):
        with runner.running(scene, sync.load(spec)) as run:
            for frame in (0, 1, 5, 60, 120):
                run.advance(frame - run.frame)
                assert diagnosis.soft_drawn_as_rigid(run) == "", (scene, frame)
                assert "is a soft body" not in diagnosis.diagnose_problems(run), (scene, frame)
