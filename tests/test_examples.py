"""Every example app of the installed FURY (``examples/vtk`` or ``examples/pygfx``) gets the verdict its
docstring's EXPECT line states: right apps pass every check and a perturbed run, wrong apps fail the
stated check with the stated diagnosis (and a mistake outside the catalogue gets none).

The full table (three perturbed runs each) is ``python -m conformance app-table examples/BACKEND``
(``docs/app-examples-*.md``); here right apps get one perturbed run and wrong apps none unless their
mistake only shows under the kit's events, to keep CI short.
"""

from __future__ import annotations

from pathlib import Path

import pytest

import confusion_records
from conformance import backends
from conformance.apps import examples
from conformance.apps.verdict import lead

EXAMPLES = Path(__file__).resolve().parent.parent / "examples" / backends.NAME
APPS = sorted(p for p in EXAMPLES.rglob("*.py") if not p.name.startswith("_"))


def test_there_are_right_and_wrong_examples():
    expected = [examples.expectation(p) for p in APPS]
    assert sum(e.passes for e in expected) >= 2 and sum(not e.passes for e in expected) >= 8


@pytest.mark.parametrize("app", APPS, ids=lambda p: str(p.relative_to(EXAMPLES)))
def test_example_gets_the_verdict_it_states(app):
    expected = examples.expectation(app)
    runs = 1 if expected.passes or expected.check == "perturbed" else 0
    outcome = examples.judge_example(app, perturbed=runs)
    assert outcome.agrees, (f"{app}: expected {outcome.expected}, got {outcome.verdict()}"
                            + (f"\n{outcome.error}" if outcome.error else ""))
    if not expected.passes and expected.diagnosis is not None:  # issue 48: the line the report leads with
        named = lead(d for diagnoses in outcome.failed.values() for d in diagnoses)
        confusion_records.assert_named_no_worse("apps", app.relative_to(EXAMPLES.parent.parent).as_posix(), actual=named,
                                                expected=expected.diagnosis, where=outcome.verdict())
