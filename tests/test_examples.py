"""Every example app of the installed FURY (``examples/vtk`` or ``examples/pygfx``) gets the verdict its
docstring's EXPECT line states: right apps pass every check and a perturbed run, wrong apps fail the
stated check with the stated diagnosis (and a mistake outside the catalogue gets none).

The full table (three perturbed runs each) is ``python -m conformance app-table examples/BACKEND``
(``docs/app-examples-*.md``); here right apps get one perturbed run and wrong apps none unless their
mistake only shows under the kit's events, to keep CI short. The judgements start with the session in
a worker process beside this one (``background``), so these tests come last and read them.
"""

from __future__ import annotations

from pathlib import Path

import pytest

import background
from conformance import backends
from conformance.apps import examples

EXAMPLES = Path(__file__).resolve().parent.parent / "examples" / backends.NAME
APPS = sorted(p for p in EXAMPLES.rglob("*.py") if not p.name.startswith("_"))


def test_there_are_right_and_wrong_examples():
    expected = [examples.expectation(p) for p in APPS]
    assert sum(e.passes for e in expected) >= 2 and sum(not e.passes for e in expected) >= 8


def _judgement(app: Path):
    """The run of ``app``'s judgement (key and call for :mod:`background`)."""
    expected = examples.expectation(app)
    runs = 1 if expected.passes or expected.check == "perturbed" else 0
    return f"example:{app}", background.InWorker(examples.judge_example, (app,), {"perturbed": runs})


def background_runs(items) -> dict:
    """Every selected app's judgement, in the session's worker process."""
    apps = [item.callspec.params["app"] for item in items if item.originalname == "test_example_gets_the_verdict_it_states"]
    return {key: (0, call) for key, call in map(_judgement, apps)}


@pytest.mark.parametrize("app", APPS, ids=lambda p: str(p.relative_to(EXAMPLES)))
def test_example_gets_the_verdict_it_states(app):
    outcome = background.result(*_judgement(app))
    assert outcome.agrees, (f"{app}: expected {outcome.expected}, got {outcome.verdict()}"
                            + (f"\n{outcome.error}" if outcome.error else ""))
