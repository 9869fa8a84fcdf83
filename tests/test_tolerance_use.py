"""Tolerance use: each allowance's worst right-sync figure, and the loose ones flagged (a reason to keep
each, or it is reported as unexplained)."""

from __future__ import annotations

import pytest

from conformance.discrimination import tolerance_use
from conformance.discrimination.verdicts import Outcome


def _record(check="test_a", scene="chain", error=1e-7, tolerance=1e-6, normals=None):
    return {"check": check, "scene": scene, "outcome": "passed",
            "worst": {"error": error, "tolerance": tolerance, "target": "box", "frame": 3},
            "worst_normals": normals}


def _image(kind="golden", metrics=None, limits=None, scene="chain", frame=10):
    return {"kind": kind, "scene": scene, "frame": frame, "metrics": metrics or {}, "limits": limits or {},
            "details": {"tolerance_set": "same-renderer"}}


def test_use_is_the_share_of_the_allowance_on_either_side_of_a_bound():
    found = tolerance_use.uses("s", [_record(error=5e-7, tolerance=1e-6)],
                               [_image(metrics={"sync: differing_fraction": 0.002}, limits={"sync: differing_fraction": 0.004}),
                                _image("silhouette", metrics={"iou": 0.97}, limits={"iou": 0.94}),
                                _image("golden", metrics={"badly": 0.0}, limits={"badly": 0.0}),  # 0 allowed: not a tolerance
                                _image("golden", metrics={"shaded_fraction": 0.0}, limits={"shaded_fraction": 1.0})])  # off
    by = {u.allowance: u.use for u in found}
    assert by == pytest.approx({"vertex position": 0.5, "golden sync: differing_fraction (same-renderer)": 0.5,
                                "silhouette iou": 0.5})


def test_the_worst_use_over_syncs_and_scenes_is_kept_and_the_loose_ones_are_flagged():
    found = (tolerance_use.uses("a", [_record(error=2e-7)], [])
             + tolerance_use.uses("b", [_record(scene="pendulum", error=6e-7)], [])
             + tolerance_use.uses("a", [_record(normals={"error": 1e-7, "tolerance": 1e-4, "target": "s", "frame": 1})], []))
    worst = tolerance_use.worst_uses(found)
    assert worst["vertex position"].use == pytest.approx(0.6) and "pendulum" in worst["vertex position"].where
    text = tolerance_use.markdown(worst, reasons={})
    assert "| normals angle | 0.1% **loose** |" in text, text
    assert "| vertex position | 60.0% |" in text, text
    assert "- **normals angle**: no reason written yet" in text
    assert tolerance_use.unexplained(worst, reasons={}) == ["normals angle"]
    assert tolerance_use.unexplained(worst, reasons={"normals angle": "keep: …"}) == []


def test_the_command_refuses_figures_from_a_sync_that_fails(monkeypatch, capsys):
    from conformance import cli
    from conformance.discrimination import verdicts

    monkeypatch.setattr(verdicts, "check_all", lambda specs, **kwargs: [Outcome(s, 1, [_record()]) for s in specs])
    assert cli.main(["tolerance-use", "wrong_syncs:DoesNothing"]) == 1
    assert "wrong_syncs:DoesNothing failed the checks, so it is not a right sync" in capsys.readouterr().out


def test_the_command_writes_the_table_with_the_command_that_made_it(tmp_path, monkeypatch):
    from conformance import cli
    from conformance.discrimination import verdicts

    monkeypatch.setattr(verdicts, "check_all", lambda specs, **kwargs: [
        Outcome(s, 0, [_record()], images=[_image(metrics={"sync: flip_mean": 0.01}, limits={"sync: flip_mean": 0.02})])
        for s in specs])
    out = tmp_path / "use.md"
    assert cli.main(["tolerance-use", "reference", "--out", str(out), "--", "-k", "chain"]) == 0
    text = out.read_text(encoding="utf-8")
    assert "Made by `python -m conformance tolerance-use reference -- -k chain`" in text, text
    assert "| golden sync: flip_mean (same-renderer) | 50.0% |" in text, text
