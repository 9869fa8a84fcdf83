"""A failing vertex check shows in ``report.html``: the failing frame as the sync drew it, with the
outline of where pyBullet has each failing body, its diagnosis and its ``reproduce:`` command
(conformance.reports.misplaced); a right sync's run has no such card."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from conformance.rendering import outline

CHECKS = "(test_vertices_match_poses_every_frame or test_vertices_match_through_teleports_and_kicks) and free_fall"


def _run(pytester, monkeypatch, sync: str):
    monkeypatch.setenv("PYTHONPATH", str(Path(__file__).parent))
    results = pytester.path / "results"
    outcome = pytester.runpytest_subprocess("--pyargs", "conformance", "-p", "no:cacheprovider", "-k", CHECKS,
                                            "--sync", sync, "--conformance-results", str(results),
                                            "--hypothesis-profile", "default")  # not the "ci" Hypothesis picks under $CI
    records = []
    for path in sorted(results.glob("records-*.jsonl")):
        records += [json.loads(line) for line in path.read_text().splitlines()]
    return outcome, results, [r for r in records if r["kind"] == "vertices"]


def test_a_failing_vertex_check_is_pictured_with_pybullets_outline_and_its_diagnosis(pytester, monkeypatch):
    outcome, results, cards = _run(pytester, monkeypatch, "wrong_syncs:OneStepLate")
    outcome.assert_outcomes(failed=2)
    # One card per failing check: the property's examples tried before the reported one are not pictured.
    assert sorted(c["nodeid"].split("::")[-1] for c in cards) == [
        "test_vertices_match_poses_every_frame[free_fall]", "test_vertices_match_through_teleports_and_kicks[free_fall]"]
    for card in cards:
        assert not card["passed"] and card["metrics"]["error_m"] > card["limits"]["error_m"]
        # A step late, or, at a frame with a teleport or kick, at the pose before it (the same mistake).
        assert card["details"]["diagnosis"].startswith(("drawn exactly at pyBullet's pose of the previous step",
                                                        "drawn at the pose before the")), card["details"]
        assert card["reproduce"].startswith("python -m conformance check free_fall --sync wrong_syncs:OneStepLate")
        picture = np.asarray(Image.open(results / card["images"]["outlined"]).convert("RGB"))
        assert (picture == outline.OUTLINE_COLOUR).all(axis=2).sum() > 20, "no outline drawn"
    page = (results / "report.html").read_text()
    assert 'data-kind="vertices"' in page and 'class="diagnosis"' in page and "pyBullet&#x27;s outline" in page


@pytest.mark.full("a whole run of a right sync for its report: CI's kill-rate runs pass every right sync")
def test_a_right_sync_gets_no_vertex_card(pytester, monkeypatch):
    outcome, results, cards = _run(pytester, monkeypatch, "reference")
    outcome.assert_outcomes(passed=2)
    assert cards == []
