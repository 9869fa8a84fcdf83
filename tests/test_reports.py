"""The verdict and kill-rate tables: what they say, and how they land in the README."""

from __future__ import annotations

from pathlib import Path

import pytest

from conformance import cli
from conformance.discrimination import verdicts
from conformance.checks import survey
from conformance.commands.common import replace_block
from conformance.errors import ConformanceError


def _record(check, scene, outcome, ratio=None):
    worst = {"ratio": ratio, "error": ratio * 1e-6} if ratio is not None else None
    return {"check": check, "scene": scene, "outcome": outcome, "worst": worst,
            "message": f"x is off [{scene}, frame 3, sync 'w']" if outcome == "failed" else ""}


def test_kill_rate_table_counts_survivors_and_rejected_right_ones():
    wrong = [verdicts.Outcome("w:Killed", 1, [_record("test_a", "free_fall", "failed")]),
             verdicts.Outcome("w:Survivor", 0, [_record("test_a", "free_fall", "passed")]),
             verdicts.Outcome("w:Broken", 4, [])]
    right = [verdicts.Outcome("r:Good", 0, [_record("test_a", "chain", "passed")]),
             verdicts.Outcome("r:Bad", 1, [_record("test_b", "chain", "failed")])]
    table = verdicts.kill_rate_table(wrong, right, {"w:Killed": "Wrong: forgets a body"})
    assert table.startswith("Kill rate: 1/3 wrong implementations rejected; 1/2 right implementations accepted.")
    assert "| `w:Killed` | Wrong: forgets a body | killed | test_a [free_fall] |" in table
    assert "| `w:Survivor` | wrong | survived |  |" in table
    assert "| `w:Broken` | wrong | ERROR |  |" in table
    assert "| `r:Bad` | right | REJECTED | test_b [chain] |" in table


def test_verdict_table_marks_passes_with_the_worst_error_and_failures_with_their_kinds():
    failed = dict(_record("test_a", "chain", "failed", 3e4), kinds={"vertices": survey.figure(
        value=0.03, limit=1e-6, unit="m", frame=3, target="link_0", message="x is off [chain, frame 3, sync 'w']")})
    outcomes = [verdicts.Outcome("ok", 0, [_record("test_a", "chain", "passed", 0.5)]),
                verdicts.Outcome("bad", 1, [failed, _record("test_b", "chain", "passed")])]
    table = verdicts.verdict_tables(outcomes)
    assert "| chain | ✓ 5.0e-07 m (0.5×tol) | ✗ 1/2: vertices 0.03 m (3e+04×tol, frame 3) |" in table
    assert ("- `bad` · **vertices**: worst 0.03 m (3e+04×tol, frame 3) on chain, 'link_0', `test_a`; in 1 check on "
            "1 scene (chain): x is off [chain, frame 3, sync 'w']") in table


def test_a_kept_run_comes_back_with_its_backend_and_sits_beside_this_ones(tmp_path):
    """``--json`` keeps a run with the FURY that made it; ``--beside`` puts it next to this backend's,
    every cell naming its FURY, and a survivor on one backend stands out in the kill-rate table."""
    from conformance import backends

    kept = tmp_path / "other.json"
    mine = [verdicts.Outcome("w:Caught", 1, [_record("test_a", "chain", "failed")]),
            verdicts.Outcome("r:Good", 0, [_record("test_a", "chain", "passed", 0.5)])]
    verdicts.save_run(str(kept), mine, {"w:Caught": "wrong", "r:Good": "right"})
    label, outcomes, roles = verdicts.load_run(str(kept))
    assert label == f"FURY {backends.fury_version()} ({backends.NAME})"
    assert [(o.spec, o.exitstatus, o.records) for o in outcomes] == [(o.spec, o.exitstatus, o.records) for o in mine]
    assert roles == {"w:Caught": "wrong", "r:Good": "right"}
    survived = [verdicts.Outcome("w:Caught", 0, [_record("test_a", "chain", "passed")])]
    table = verdicts.kill_rate_beside([("FURY 0.12.0 (vtk)", outcomes[:1], outcomes[1:]),
                                       ("FURY 2.0.0 (pygfx)", survived, outcomes[1:])], {"w:Caught": "forgets"})
    assert table.startswith("Kill rate: FURY 0.12.0 (vtk): 1/1 wrong implementations rejected, 1/1 right ones accepted. "
                            "FURY 2.0.0 (pygfx): 0/1 wrong implementations rejected")
    assert "| `w:Caught` | forgets | killed: test_a [chain] | **survived** |" in table
    assert "| `r:Good` |  | passed | passed |" in table
    scenes = verdicts.verdicts_beside([("FURY 0.12.0 (vtk)", outcomes), ("FURY 2.0.0 (pygfx)", survived)])
    assert "| chain | **FURY 0.12.0**: ✗ 1/1: test_a from frame 3<br>**FURY 2.0.0**: ✓ | **FURY 0.12.0**: ✓ 5.0e-07 m (0.5×tol)<br>**FURY 2.0.0**: – |" in scenes


def test_a_file_that_is_not_a_kept_run_is_one_clear_error(tmp_path):
    bad = tmp_path / "verdicts.md"
    bad.write_text("| scene |", encoding="utf-8")
    with pytest.raises(ConformanceError, match=r"--beside .*verdicts.md: not a run kept by --json .*in the other backend's environment"):
        verdicts.load_run(str(bad))


def test_implementations_are_the_modules_public_list():
    assert verdicts.implementations("right_syncs")[:2] == ["right_syncs:IncrementalSync", "right_syncs:PerTargetSync"]
    assert "right_syncs:vectorised_vertex_sync" in verdicts.implementations("right_syncs")


def test_what_an_implementation_is_comes_from_its_docstring():
    assert verdicts.what_it_is("wrong_syncs:VelocityGated") == (
        'after the first frame, skips bodies whose velocity is exactly zero ("a body at rest has not moved")')
    assert verdicts.what_it_is("right_syncs:UserMatrixSync").startswith("per-actor ")  # user matrices or local.matrix
    # a colon inside parentheses does not end the clause
    assert verdicts.what_it_is("order_syncs:StaticSetAtFrameZero").startswith(
        "decides once, at start-up, which bodies are static (mass 0: the ground, walls, a fixed base) and, ")


def test_tables_replace_only_their_block_of_the_readme(tmp_path):
    readme = tmp_path / "README.md"
    readme.write_text("intro\n<!-- conformance:kill-rate -->\nold table\n<!-- /conformance:kill-rate -->\nrest\n")
    replace_block(str(readme), "kill-rate", "| new |\n")
    assert readme.read_text() == "intro\n<!-- conformance:kill-rate -->\n| new |\n<!-- /conformance:kill-rate -->\nrest\n"
    assert not (tmp_path / "README.md.tmp").exists()


def test_readme_without_the_markers_is_a_clear_error_and_is_left_alone(tmp_path):
    readme = tmp_path / "README.md"
    readme.write_text("no markers here\n")
    with pytest.raises(ConformanceError, match=r"needs one line '<!-- conformance:verdicts -->' followed by"):
        replace_block(str(readme), "verdicts", "| t |")
    assert readme.read_text() == "no markers here\n"
    with pytest.raises(ConformanceError, match=r"cannot read it"):
        replace_block(str(tmp_path / "missing.md"), "verdicts", "| t |")


@pytest.mark.full("whole `run` commands with wrong and right syncs: the command's exit status end to end, not one of CI's guarantees")
def test_run_command_is_pytest_on_the_kit_and_says_so_in_its_exit_status(monkeypatch, capfd):
    """``python -m conformance run`` (what ``./kit run`` calls): 0 for a right sync, 1 for a wrong one,
    and no warning that the kit could not be assert-rewritten."""
    from pathlib import Path

    monkeypatch.setenv("PYTHONPATH", str(Path(__file__).parent))
    select = ["-q", "-k", "free_fall and poses_every_frame"]
    assert cli.main(["run", "--sync", "right_syncs:PerTargetSync", *select]) == 0
    assert cli.main(["run", "--sync", "wrong_syncs:DoesNothing", *select]) == 1
    out, err = capfd.readouterr()
    assert "1 passed" in out and "1 failed" in out and "[free_fall" in out
    assert "PytestAssertRewriteWarning" not in out + err


def test_run_checks_the_sync_the_ini_names_as_pytest_would(monkeypatch, capfd, tmp_path):
    """Without --sync, ``run`` leaves the choice to the plug-in (the ini's conformance_sync, then
    $CONFORMANCE_SYNC, then reference): it used to pass --sync reference and ignore the ini."""
    from pathlib import Path

    monkeypatch.setenv("PYTHONPATH", str(Path(__file__).parent))
    monkeypatch.delenv("CONFORMANCE_SYNC", raising=False)
    monkeypatch.chdir(tmp_path)
    (tmp_path / "pytest.ini").write_text("[pytest]\nconformance_sync = wrong_syncs:DoesNothing\n")
    assert cli.main(["run", "-q", "-k", "free_fall and poses_every_frame"]) == 1
    out, _ = capfd.readouterr()
    assert "sync 'wrong_syncs:DoesNothing'" in out and "1 failed" in out, out[-2000:]


def test_verdicts_runs_in_survey_mode_and_kill_rate_stops_at_the_first_failure(monkeypatch, capsys):
    argv = verdicts.command("s", survey=True, report="r.json", results="pics")
    assert "--conformance-survey" in argv and argv[argv.index("--conformance-results") + 1] == "pics"
    argv = verdicts.command("s", stop_at_first=True, results="pics", pytest_args=["--conformance-results=mine"])
    assert "-x" in argv and "--conformance-survey" not in argv and "pics" not in argv
    calls = []

    def check_all(specs, **options):
        calls.append(options)
        return [verdicts.Outcome(spec, 0, []) for spec in specs]

    monkeypatch.setattr(verdicts, "check_all", check_all)
    assert cli.main(["verdicts", "reference"]) == 0
    assert calls.pop()["survey"] is True
    assert cli.main(["kill-rate", "--wrong", "wrong_syncs", "--right", "right_syncs"]) == 1  # nothing killed here
    assert [c.get("survey", False) for c in calls] == [False, False] and calls[0]["stop_at_first"] is True
    from conformance import backends

    out = capsys.readouterr().out  # both tables say which FURY they were made on
    assert out.count(f"Checked on the {backends.describe()}.") == 2


def test_a_page_written_says_it_is_generated_and_by_which_command(monkeypatch, tmp_path, capsys):
    """The pages docs/ links to (verdicts, kill rate) open with the command that made them, as given: a reader
    knows not to edit them, and how to make them again; what is printed on the terminal does not carry it."""
    monkeypatch.setattr(verdicts, "check_all", lambda specs, **options: [verdicts.Outcome(spec, 0, []) for spec in specs])
    for argv in (["verdicts", "reference", "--out", str(tmp_path / "v.md")],
                 ["kill-rate", "--wrong", "wrong_syncs", "--right", "right_syncs", "--out", str(tmp_path / "k.md")]):
        cli.main(argv)
        lines = Path(argv[-1]).read_text(encoding="utf-8").splitlines()
        command = "python -m conformance " + " ".join(argv)
        assert lines[:4] == [f"<!-- generated by `{command}`; do not edit -->", "", f"Made by `{command}`.", ""]
        assert lines[4].startswith("Checked on the "), lines[:6]
    assert "generated by" not in capsys.readouterr().out


def test_verdicts_refuses_a_spec_that_does_not_load_before_running_anything(monkeypatch, capsys):
    monkeypatch.setattr(verdicts, "check_all", lambda *a, **k: pytest.fail("nothing should run"))
    assert cli.main(["verdicts", "reference", "no_such_module:Sync"]) == 2
    assert "error: sync implementation 'no_such_module:Sync': importing module 'no_such_module' failed" in capsys.readouterr().err


def test_the_image_tolerance_page_is_its_generators_output_under_its_header():
    """docs/image-tolerances.md opens with what ``measure_tolerances --out`` writes before its tables, so the
    page is the command's output and nothing hand-written that a regeneration would lose."""
    from pathlib import Path

    from conformance.rendering import measure_tolerances

    header = measure_tolerances._header("docs/image-tolerances.md")
    assert header.startswith("# ") and "<!-- generated by `python -m conformance.rendering.measure_tolerances --out " \
                                        "docs/image-tolerances.md`; do not edit -->" in header
    page = (Path(__file__).resolve().parent.parent / "docs" / "image-tolerances.md").read_text(encoding="utf-8")
    assert page.startswith(header + "| change | same-renderer: pixels > 2 |"), page[:len(header) + 80]
