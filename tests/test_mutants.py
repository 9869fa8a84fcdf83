"""Machine-made mutants (issue 17, point 2; :mod:`conformance.discrimination.mutants`): the mutants are made and named
the same way every time, each run is classified right (not viable, killed, raised, crashed, timed out,
survived), and the fast sample of the full run's mutants stays 100 % killed on the backend in force.

The full run (every mutant of ``frames.py``, the backend's reference and the einsum closure) takes an
hour or more here: ``python -m conformance mutants --results … --out docs/mutants-<backend>.md``
(docs/discrimination.md#machine-made-mutants); CI keeps the sample.
"""

from __future__ import annotations

import sys
import threading

import pytest

import background
from conformance import backends
from conformance.discrimination import mutants
from conformance.discrimination.verdicts import Outcome

#: A run of one cheap check on one scene, for the hand-made mutants (a whole run costs a minute).
ONE_CHECK = ["-k", "test_vertices_match_poses_every_frame and chain"]


def _record(outcome="failed", message="'a' (body 0) vertex 3 is drawn at …: error 0.1 m > tolerance 1e-06 m", kinds=None):
    return {"check": "test_vertices_match_poses_every_frame", "scene": "chain", "outcome": outcome,
            "message": message, "kinds": kinds or {}}


@pytest.mark.parametrize("outcome, state", [
    (Outcome("m:S", 4, [], "ERROR: sync implementation 'm:S' could not be imported: SyntaxError"), "not viable"),
    (Outcome("m:S", 1, [_record(message="sync implementation 'm:S' raised while being set up for scene 'chain': ValueError")]),
     "not viable"),
    (Outcome("m:S", 1, [_record()]), "killed"),
    (Outcome("m:S", 1, [_record(message="sync implementation 'm:S' raised on scene 'chain' at step 3: IndexError")]), "raised"),
    (Outcome("m:S", 1, [_record(message="the process crashed", kinds={"crashed": {}})]), "crashed"),
    (Outcome("m:S", 1, [_record(message="sync implementation 'm:S' did not return within 10 s on scene 'chain'")]), "timed out"),
    (Outcome("m:S", 0, [_record("passed", "")]), "survived"),
    (Outcome("m:S", 2, [], "INTERNALERROR> display gone"), "error"),
    (Outcome("m:S", 1, [_record("passed", "")]), "error"),
])
def test_a_run_is_classified_by_what_decided_it(outcome, state):
    assert mutants.classify(outcome)[0] == state


def test_mutants_are_made_and_named_the_same_way_every_time():
    for name in mutants.target_names():
        target = mutants.TARGETS[name]()
        made, again = mutants.generate(target), mutants.generate(target)
        assert made and [m.id for m in made] == [m.id for m in again]
        assert len({m.id for m in made}) == len(made), f"{name}: two mutants share an id"
        original = (mutants.ROOT / target.path).read_text(encoding="utf-8")
        for m in made:
            assert m.source != original and m.diff.startswith("-") and "\n+" in m.diff, m
            if target.functions:
                assert m.function.split(".")[0] in target.functions, m


def test_score_leaves_out_what_is_not_a_sync():
    results = [mutants.Result(str(i), "t", state, 1.0) for i, state in enumerate(
        ["killed", "raised", "survived", "not viable", "error", "timed out"])]
    assert mutants.score(results) == (3, 4)


def test_the_page_lists_every_survivor_with_its_verdict():
    target = mutants.TARGETS["reference"]()
    made = mutants.generate(target)[:3]
    results = {made[0].id: mutants.Result(made[0].id, "reference", "killed", 9.0, "test_golden_render", "chain"),
               made[1].id: mutants.Result(made[1].id, "reference", "survived", 40.0),
               made[2].id: mutants.Result(made[2].id, "reference", "survived", 41.0)}
    text = mutants.markdown({"reference": made}, results, {made[1].id: "equivalent: it is overwritten"},
                            title="t", made_by="python -m conformance mutants")
    assert "**Mutation score: 1/3 = 33.3 %**" in text, text
    assert f"| `{made[1].id}` | reference |" in text and "equivalent: it is overwritten |" in text, text
    assert f"| `{made[2].id}` | reference |" in text and "**no verdict** |" in text, text
    assert "| `test_golden_render` | 1 |" in text, text


def test_the_verdicts_file_is_read_and_checked(tmp_path):
    path = tmp_path / "verdicts.txt"
    path.write_text("# comment\n0123456789 equivalent: dead code\n", encoding="utf-8")
    assert mutants.read_verdicts(path) == {"0123456789": "equivalent: dead code"}
    path.write_text("short equivalent\n", encoding="utf-8")
    with pytest.raises(mutants.ConformanceError, match="1: should be"):
        mutants.read_verdicts(path)
    assert set(mutants.read_verdicts()) <= set(_made()) | set(mutants.read_verdicts()), "the kept verdicts parse"


def _hand_made(source: str, factory: str = "Sync") -> mutants.Result:
    """Judge a hand-made "mutant": ``source`` as the sync module, one cheap check run on it."""
    target = mutants.Target("hand-made", "conformance/implementations/frames.py", lambda text: {mutants.SYNC_MODULE: text}, factory)
    mutant = mutants.Mutant("hand-made", "0000000000", "Sync", 1, "hand-made", "", source)
    return mutants.judge(target, mutant, pytest_args=ONE_CHECK)


@pytest.mark.parametrize("source, state", [
    ("import a_module_that_is_nowhere\n", "not viable"),
    ("class Sync:\n    def __init__(self, world):\n        raise ValueError('no')\n", "not viable"),
    ("class Sync:\n    def __init__(self, world):\n        pass\n\n    def __call__(self):\n        pass\n", "killed"),
    ("from conformance.implementations.reference import ReferenceSync as Sync\n", "survived"),
], ids=["fails-to-import", "raises-at-set-up", "does-nothing", "the-reference"])
def test_hand_made_mutants_are_classified_by_a_real_run(source, state):
    result = _hand_made(source)
    assert result.state == state, result


_MADE: dict = {}
_MADE_LOCK = threading.Lock()


def _made() -> dict:
    """Every mutant the kit makes, by id: ``(target name, mutant)``, made once a session (a making of all
    of them costs seconds, and each sample test made them all again)."""
    with _MADE_LOCK:
        if not _MADE:
            _MADE.update({m.id: (name, m) for name in mutants.target_names() for m in mutants.generate(mutants.TARGETS[name]())})
    return _MADE


def _sample_run(ident: str):
    """The run judging sample mutant ``ident`` (key and callable for :mod:`background`); None if it is no
    longer made."""

    def judge():
        found = _made().get(ident)
        return None if found is None else mutants.judge(mutants.TARGETS[found[0]](), found[1])

    return f"mutant:{ident}", judge


def background_runs(items) -> dict:
    """The sample's runs start with the session, beside this process's other tests (``background``). The
    mutants are made here first, in this thread: making them imports mutmut and libcst, and an import in
    a run's thread while a ``pytester`` test in this one puts ``sys.modules`` back as it found it fails
    mid-way (seen in CI, 2026-11-28: ``KeyError: 'libcst.matchers'``, every sample test failed)."""
    runs = dict((key, (0.5, call)) for item in items if item.originalname == "test_the_fast_sample_is_killed"
                for key, call in [_sample_run(item.callspec.params["ident"])])
    if runs:
        _made()
    return runs


@pytest.mark.parametrize("ident", mutants.SAMPLE.get(backends.NAME, ()))
def test_the_fast_sample_is_killed(ident):
    """The fixed sample of the full run's mutants (each killed by an early check there) must stay killed:
    a change to a check that lets one through fails here, per commit, before the hour-long full run."""
    result = background.result(*_sample_run(ident))
    assert result is not None, (f"sample mutant {ident} is no longer made (its code changed): pick another from the full "
                                "run's page and update conformance.discrimination.mutants.SAMPLE")
    mutant = _made()[ident][1]
    assert result.state == "killed", f"{mutant.function} line {mutant.line}:\n{mutant.diff}{result}"


def test_the_sample_s_mutants_are_made_before_its_runs_start(monkeypatch):
    """The planner makes the mutants in the session's thread, so no run's thread imports mutmut or libcst
    while a ``pytester`` test puts ``sys.modules`` back (``background_runs``)."""
    from types import SimpleNamespace

    monkeypatch.setattr(sys.modules[__name__], "_MADE", {})
    item = SimpleNamespace(originalname="test_the_fast_sample_is_killed", callspec=SimpleNamespace(params={"ident": "any"}))
    runs = background_runs([item])
    assert list(runs) == ["mutant:any"] and _MADE, "the sample's runs were planned before its mutants were made"
