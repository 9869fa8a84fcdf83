"""The confusion matrix of diagnoses (issue 48; :mod:`conformance.discrimination.confusion`): a case's cell
is right, none or a wrong name; a cell that gets worse is seen; the page counts what it is given; a failing
app's report leads with its most explanatory diagnosis; a diagnosis kept as text is counted by its name; and
every wrong sync of ``tests/`` states the mistake it makes. The CI tests that hold each corpus to its
committed record are in ``test_discrimination`` (wrong syncs), ``test_examples`` (example apps) and
``test_zoo`` (the zoo's slice)."""

from __future__ import annotations

import functools

import pytest

import order_syncs
import soft_syncs
import wrong_syncs
from conformance.apps.verdict import DIAGNOSES, LEAD_ORDER, Verdict, lead, lead_line
from conformance.discrimination import confusion, confusion_cases, verdicts
from conformance.errors import ConformanceError
from conformance.judge import diagnosis

pytestmark = pytest.mark.fury_free("verdicts and tables made by hand")


def test_a_cell_is_right_none_or_the_wrong_name():
    assert confusion.cell("previous-step", "previous-step") == "right"
    assert confusion.cell("previous-step", "") == "none"
    # a tie names neither of its two, and is wrong for any other mistake
    assert confusion.cell("before-own-move", "late-or-own-move") == confusion.cell("previous-step", "late-or-own-move") == "none"
    assert confusion.cell("wxyz", "late-or-own-move") == "other:late-or-own-move"
    assert confusion.cell("previous-step", "skipped") == "other:skipped"
    assert confusion.cell("-", "") == "right"  # outside the catalogue: silence is the right answer
    assert confusion.cell("-", "never-moved") == "other:never-moved"


@pytest.mark.parametrize("before, now, is_worse", [
    ("right", "right", False), ("right", "none", True), ("right", "other:x", True), ("none", "right", False),
    ("none", "none", False), ("none", "other:x", True), ("other:x", "none", False), ("other:x", "other:x", False),
    ("other:x", "other:y", True)])
def test_a_cell_that_gets_worse_is_seen(before, now, is_worse):
    assert confusion.worse(before, now) is is_worse


def test_the_page_counts_each_row_and_lists_the_wrong_names():
    cases = [confusion.Case("syncs", "wrong_syncs:A", "conjugate", "conjugate"),
             confusion.Case("syncs", "wrong_syncs:B", "conjugate", ""),
             confusion.Case("syncs", "wrong_syncs:C", "conjugate", "wxyz", where="test_x [crossing]"),
             confusion.Case("syncs", "wrong_syncs:D", "-", "")]
    page = confusion.markdown([("FURY 0.12", cases)])
    assert "| syncs | FURY 0.12 | 4 | 2 (50 %) | 1 | 1 |" in page, page
    assert "| `conjugate` | 3 | 1 | 1 | 1 (`wxyz` 1) |" in page, page
    assert "| `-` (outside the catalogue: none may be named) | 1 | 1 | 0 | 0 |" in page, page
    assert "- FURY 0.12: `wrong_syncs:C` (conjugate) named `wxyz` in test_x [crossing]" in page, page


def test_a_record_is_kept_whole_and_a_broken_one_says_how_to_make_it(tmp_path):
    cases = [confusion.Case("apps", "examples/vtk/wrong/a.py", "wxyz", "conjugate", "attached"),
             confusion.Case("zoo", "m.urdf links wxyz", "wxyz", "wxyz", "attached", ["conjugate"])]
    confusion.save(tmp_path / "c.json", cases, {"fury": "FURY 0.12", "made_by": "by hand"})
    meta, kept = confusion.load(tmp_path / "c.json")
    assert meta["fury"] == "FURY 0.12"
    assert kept == [cases[0], confusion.Case("zoo", "m.urdf links wxyz", "wxyz", "wxyz")]  # the zoo's: cells only
    assert confusion.record(kept) == {"apps": {"examples/vtk/wrong/a.py": "other:conjugate"},
                                      "zoo": {"m.urdf links wxyz": "right"}}
    (tmp_path / "bad.json").write_text("{\"cases\": [")
    with pytest.raises(ConformanceError, match=r"bad.json: cannot read it as a confusion record .*--json PATH"):
        confusion.load(tmp_path / "bad.json")


def test_the_lead_order_holds_every_diagnosis_once():
    assert sorted(LEAD_ORDER) == sorted(DIAGNOSES)


def test_a_run_leads_with_the_most_explanatory_diagnosis_whatever_the_order():
    assert lead(["not-its-shape", "other-body", "scaled"]) == lead(["scaled", "not-its-shape"]) == "scaled"
    assert lead(["never-moved", "previous-step"]) == "previous-step"
    assert lead([]) == ""
    verdicts_ = {"drawn": Verdict("drawn", False, ["link 0 moves but no drawn vertex follows it"]),
                 "placed": Verdict("placed", False, ["drawn at 1.6 times its size"], ["scaled"]),
                 "pictured": Verdict("pictured", False, ["not where pyBullet draws it"], ["not-its-shape"])}
    assert lead_line(verdicts_) == f"the mistake, most likely (placed names it): {DIAGNOSES['scaled']}"
    assert lead_line({"drawn": verdicts_["drawn"]}) == ""  # nothing named: nothing claimed


def test_a_diagnosis_kept_as_text_is_counted_by_its_name():
    for name, words in diagnosis.MISTAKES.items():
        line = "diagnosis: " + words.format(frame=7, event="teleport", call="getLinkState(...)[0:2]", order="x, y, z",
                                            other="'b'")
        assert diagnosis.name_of(line) == name, line
    for name, words in diagnosis.NORMAL_MISTAKES.items():
        assert diagnosis.name_of(words.format(frame=3, announce="Modified()")) == name
    late = diagnosis.SOFT_WORDS["late-or-once"].format(frame=1)
    assert diagnosis.name_of(late) == "late-or-once"  # two mistakes not told apart yet: counted as neither
    assert confusion.cell("never-moved", "late-or-once") == confusion.cell("previous-step", "late-or-once") == "none"
    assert confusion.cell("-", "late-or-once") == "other:late-or-once"
    posed = diagnosis.SOFT_WORDS["rigid-or-posed"].format(name="'cloth'")
    assert diagnosis.name_of(posed) == "rigid-or-posed"
    assert confusion.cell("drawn-as-rigid", "rigid-or-posed") == confusion.cell("soft-posed", "rigid-or-posed") == "none"
    assert confusion.cell("-", "rigid-or-posed") == "other:rigid-or-posed"
    told = diagnosis.SOFT_WORDS["never-moved"] + " (told at frame 2: at frame 1 the two draw alike)"
    assert diagnosis.name_of(told) == "never-moved"  # a note after the words is not part of them
    assert diagnosis.name_of("diagnosis: something the catalogue never wrote") == ""


@pytest.mark.parametrize("module", [wrong_syncs, order_syncs, soft_syncs])
def test_every_wrong_sync_states_the_mistake_it_makes(module):
    for spec in verdicts.implementations(module.__name__):
        assert confusion_cases.expected_of(spec)  # raises, naming the spec, when the line is missing or unknown


def test_a_wrong_sync_without_its_diagnosis_line_is_told_what_to_write(monkeypatch):
    class Unlabelled(wrong_syncs.Baseline):
        """Wrong: draws nothing new."""

    monkeypatch.setattr(wrong_syncs, "Unlabelled", Unlabelled, raising=False)
    with pytest.raises(ConformanceError, match=r"wrong_syncs:Unlabelled: its docstring states the diagnosis nowhere, "
                                               r"but should have one line 'Diagnosis: NAME'"):
        confusion_cases.expected_of("wrong_syncs:Unlabelled")


def test_the_page_is_made_from_the_records_alone_and_a_run_without_either_is_refused(tmp_path, capsys):
    from conformance import cli

    vtk = [confusion.Case("syncs", "wrong_syncs:A", "conjugate", "conjugate", "test_x [crossing]")]
    pygfx = [confusion.Case("syncs", "wrong_syncs:A", "conjugate", "", "test_x [crossing]")]
    confusion.save(tmp_path / "vtk.json", vtk, {"fury": "FURY 0.12", "made_by": "python -m conformance confusion A"})
    confusion.save(tmp_path / "pygfx.json", pygfx, {"fury": "FURY 2", "made_by": "python -m conformance confusion B"})
    page = tmp_path / "confusion.md"
    assert cli.main(["confusion", "--beside", str(tmp_path / "vtk.json"), "--beside", str(tmp_path / "pygfx.json"),
                     "--out", str(page)]) == 0  # none named wrong
    text = page.read_text()
    assert "the records beside it by `python -m conformance confusion A` and `python -m conformance confusion B`" in text
    assert "| syncs | FURY 0.12 | 1 | 1 (100 %) | 0 | 0 |" in text and "| syncs | FURY 2 | 1 | 0 (0 %) | 1 | 0 |" in text
    assert cli.main(["confusion"]) == 2
    assert "confusion: nothing to count: give a corpus" in capsys.readouterr().err


def test_a_case_named_worse_than_its_record_fails_ci_and_one_as_good_passes(monkeypatch):
    """The assertion CI holds every wrong sync, wrong app and zoo slice case to (tests/confusion_records.py):
    right to none, none to a wrong name, and one wrong name for another fail; the same cell or a better one
    passes; a case the record lacks may be silent but never named wrong."""
    import confusion_records

    monkeypatch.setattr(confusion_records, "recorded", lambda: {"apps": {"a.py": "right", "b.py": "none",
                                                                         "c.py": "other:conjugate"}})
    held = functools.partial(confusion_records.assert_named_no_worse, "apps", where="attached")
    held("a.py", actual="wxyz", expected="wxyz")
    held("b.py", actual="wxyz", expected="wxyz")
    held("c.py", actual="conjugate", expected="wxyz")
    held("new.py", actual="", expected="wxyz")
    for item, actual in (("a.py", ""), ("b.py", "conjugate"), ("c.py", "turned-shape"), ("new.py", "conjugate")):
        with pytest.raises(AssertionError, match=rf"{item} is named .*but should be named 'wxyz' .*\[apps, attached\]"):
            held(item, actual=actual, expected="wxyz")
