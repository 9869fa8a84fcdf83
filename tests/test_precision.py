"""``precision``: false alarms counted over random draws, each check's worst use of its allowances, and
the replay line of every alarm; the figures the checks note (``conformance.figures``)."""

from __future__ import annotations

import math
import os
import subprocess
import sys
from pathlib import Path

import pytest

from conformance import figures
from conformance.discrimination import precision
from conformance.checks import profiles

TESTS = Path(__file__).resolve().parent


def test_a_tally_keeps_the_worst_use_of_each_allowance():
    with figures.tally() as outer:
        figures.note("vertex position", 1e-6, 4e-6, where="a")
        with figures.tally() as inner:
            figures.note("vertex position", 3e-6, 4e-6, where="b")
            figures.note("silhouette IoU", 0.99, 0.98, at_least=True)
        figures.note("vertex position", 2e-6, 4e-6, where="c")
    assert outer["vertex position"]["use"] == pytest.approx(0.75) and outer["vertex position"]["where"] == "b"
    assert outer["vertex position"]["count"] == 3
    assert inner["silhouette IoU"]["use"] == pytest.approx(0.5)
    assert "silhouette IoU" in outer and set(inner) == {"vertex position", "silhouette IoU"}
    with figures.tally() as nan:
        figures.note("x", 1.0, 2.0)
        figures.note("x", math.nan, 2.0)
        figures.note("x", 1.5, 2.0)
    assert math.isnan(nan["x"]["use"])  # a NaN is the worst figure and stays
    figures.note("outside", 1.0, 1.0)  # no tally open: nothing happens


def _record(check, scene, outcome, use, message=""):
    return {"nodeid": f"conformance/{check}.py::{check}[{scene}]", "check": check, "scene": scene, "outcome": outcome,
            "message": message, "figures": {"vertex position": {"use": use, "measured": use, "limit": 1.0, "where": "'a' frame 3"}}}


def test_the_table_counts_runs_alarms_and_the_worst_use():
    draws = [precision.SyncDraw("reference", 1, 10, 60.0, 0, [_record("test_a", "chain", "passed", 0.2),
                                                               _record("test_a", "domino", "passed", 0.4),
                                                               _record("test_b", None, "xfailed", 9.0)]),
             precision.SyncDraw("reference", 2, 10, 60.0, 1, [_record("test_a", "chain", "failed", 1.3, "drawn at …"),
                                                               _record("test_a", "domino", "passed", 0.1)])]
    text = precision.markdown(draws, [], made_by="python -m conformance precision", backend="FURY test")
    assert "**1 false alarm** in 40 default-profile runs of 1 checks" in text
    row = next(line for line in text.splitlines() if line.startswith("| `test_a`"))
    assert row.startswith("| `test_a` | 40 | 1 | vertex position: 130.0%") and "[chain] reference, seed 2" in row
    assert "test_b" not in text  # an expected failure documents pyBullet, not a draw
    assert "`test_a[chain]`, sync `reference`, seed 2: drawn at …" in text
    assert "CONFORMANCE_DRAW_FACTOR=10 python -m pytest --pyargs conformance --sync reference -m draws" in text
    assert "--hypothesis-seed=2 -k 'test_a[chain]'" in text


def test_the_precision_profile_multiplies_the_examples_and_keeps_no_database(monkeypatch):
    from hypothesis import settings

    monkeypatch.setenv(profiles.DRAW_FACTOR, "7")
    old = settings.get_current_profile_name()
    settings.load_profile("precision")
    try:
        assert profiles.check_settings(examples=3).max_examples == 21
        assert settings.default.database is None and not settings.default.derandomize
        assert "x7 examples" in profiles.describe()
    finally:
        settings.load_profile(old)


def test_draw_seeds_follow_the_commit_or_the_variable(monkeypatch, tmp_path):
    monkeypatch.delenv(precision.SEED_VARIABLE, raising=False)
    seed, source = precision.draw_seed(TESTS.parent)
    assert source.startswith("commit ") and seed == int(source.split()[1][:8], 16)
    seed, source = precision.draw_seed(tmp_path)  # not a git checkout: the date
    assert "no git commit" in source and seed > 700_000
    monkeypatch.setenv(precision.SEED_VARIABLE, "123")
    assert precision.draw_seed(tmp_path) == (123, "$KIT_DRAW_SEED")


@pytest.mark.full("a precision run of a wrong sync end to end: the tool's own test; CI's random-draw slice runs the same code on right syncs")
def test_precision_reports_a_wrong_sync_as_a_false_alarm_with_its_replay_line(tmp_path):
    """End to end, as its users run it; a sync one step late stands for a false alarm (the command cannot
    tell a wrong sync from a wrong check: every failure of a right sync is an alarm), and its replay
    line, run as printed, fails the same check again."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(TESTS), os.environ.get("PYTHONPATH", "")])}
    out = tmp_path / "precision.md"
    done = subprocess.run([sys.executable, "-m", "conformance", "precision", "wrong_syncs:OneStepLate", "--seeds", "1",
                           "--first-seed", "4", "--factor", "1", "--out", str(out)],
                          capture_output=True, text=True, env=env, timeout=900)
    assert done.returncode == 1, done.stdout[-2000:] + done.stderr[-2000:]
    text = out.read_text()
    assert "false alarm" in text and "wrong_syncs:OneStepLate" in text
    replay = next(line for line in text.splitlines() if line.strip().startswith("replay:"))
    command = replay.split("`")[1]
    variable, _, argv = command.partition(" ")
    name, _, value = variable.partition("=")
    again = subprocess.run([sys.executable, *__import__("shlex").split(argv)[1:], "-p", "no:cacheprovider"],
                           capture_output=True, text=True, env={**env, name: value}, timeout=900)
    assert again.returncode == 1 and "failed" in again.stdout, again.stdout[-2000:]


@pytest.mark.full("a precision run end to end: the tool's own test; CI's random-draw slice runs the same code on right syncs")
def test_checks_gives_only_the_checks_it_picks_their_runs(tmp_path):
    """``--checks EXPR`` runs only what ``pytest -k EXPR`` picks of the drawing checks (how the checks that
    draw their own scene get thousands of runs cheaply), says so in the table, and keeps it in the made-by line."""
    out = tmp_path / "precision.md"
    done = subprocess.run([sys.executable, "-m", "conformance", "precision", "--seeds", "2", "--factor", "3",
                           "--checks", "test_engine_defaults or test_friction_of_one_body_alone", "--out", str(out)],
                          capture_output=True, text=True, timeout=900)
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    text = out.read_text()
    rows = [line.split("`")[1] for line in text.splitlines() if line.startswith("| `")]
    assert rows == ["test_engine_defaults", "test_friction_of_one_body_alone_does_nothing"], text
    assert "| `test_engine_defaults` | 6 | 0 |" in text, text
    assert "only the checks `-k test_engine_defaults or test_friction_of_one_body_alone` picks" in text, text
    assert "--checks 'test_engine_defaults or test_friction_of_one_body_alone'" in text, text


def test_a_journal_keeps_each_draw_and_a_run_goes_on_where_it_stopped(tmp_path, monkeypatch):
    """Each draw is appended as it finishes; a line cut short by a kill is made again, every other draw is
    not (``precision --journal``)."""
    from conformance.discrimination import verdicts

    path = tmp_path / "draws.jsonl"
    journal = precision.Journal(path)
    journal.add(precision.SyncDraw("reference", 1, 10, 5.0, 0, [_record("test_a", "chain", "passed", 0.2)]))
    with open(path, "a", encoding="utf-8") as out:
        out.write('{"kind": "sync", "draw": {"spec": "reference", "seed": 2')  # killed mid-line
    made = []

    def check(spec, *, pytest_args, env, timeout):
        made.append(pytest_args[-1])
        return verdicts.Outcome(spec, 0, [_record("test_a", "chain", "passed", 0.3)])

    monkeypatch.setattr(verdicts, "check", check)
    draws = precision.sync_draws(["reference"], [1, 2, 3], factor=10, journal=precision.Journal(path))
    assert sorted(made) == ["--hypothesis-seed=2", "--hypothesis-seed=3"]
    assert [d.seed for d in draws] == [1, 2, 3] and draws[0].records[0]["figures"]["vertex position"]["use"] == 0.2
    assert {k[2] for k in precision.Journal(path).made} == {1, 2, 3}


def test_a_band_s_figure_is_measured_from_the_law_s_value():
    """A ball that does not bounce at all (apex/drop 0, the law's value and the band's low edge) used
    100 % of [0, 1e-3] measured from the band's middle; from the law's value it uses none, and the
    band's far edge is still 100 %. Outside the band the assertion fails as before."""
    import pytest as _pytest

    from conformance.checks.physics_assertions import assert_in_band

    def use(actual, **band):
        with figures.tally() as noted:
            assert_in_band("apex/drop", actual=actual, where="[here]", **band)
        return noted["apex/drop"]["use"]

    assert use(0.0, low=0.0, high=1e-3, exact=0.0) == 0.0
    assert use(1e-3, low=0.0, high=1e-3, exact=0.0) == _pytest.approx(1.0)
    assert use(0.25 + 0.025, low=0.25, high=0.30, exact=0.25) == _pytest.approx(0.5)
    assert use(0.0, low=0.0, high=1e-3) == _pytest.approx(1.0)  # no law's value given: from the middle
    with _pytest.raises(_pytest.fail.Exception, match=r"apex/drop=0.002, but should be in \[0, 0.001\]"):
        assert_in_band("apex/drop", actual=2e-3, low=0.0, high=1e-3, where="[here]", exact=0.0)


def test_a_draw_the_kit_fails_on_is_a_rejection_in_the_journal_and_the_run_goes_on(tmp_path, monkeypatch):
    """The kit's own failure on a right app (here: the judge raising) is that draw's rejection, written to the
    journal with the error, and the later draws are made and written too; raised, it ended the journal while
    the pool made every later draw."""
    from conformance import apps

    calls = []

    def check_app(path, **kwargs):
        calls.append(path)
        if len(calls) == 1:
            raise ValueError("the judge broke")
        return apps.AppResult(str(path), 120, [], None)  # a right app: no verdict failed

    monkeypatch.setattr(apps, "check_app", check_app)
    path = tmp_path / "draws.jsonl"
    draws = precision.app_draws(["a.py", "b.py"], [1], runs=0, journal=precision.Journal(path))
    assert draws[0].error == "the kit itself failed: ValueError: the judge broke", draws[0]
    assert {k[1] for k in precision.Journal(path).made} == {"a.py", "b.py"}
