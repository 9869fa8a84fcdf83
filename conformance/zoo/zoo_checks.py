"""The zoo as a pytest run: ``test_zoo[MODEL--STYLE]``, one right program a test, each judged by app mode.

Run by ``python -m conformance zoo``, which surveys the models, writes the plan (``$CONFORMANCE_ZOO_PLAN``,
JSON: the backend, the ``[model, style]`` pairs, where the programs and the journal go, the ticks) and
runs this file with pytest, so that a run spreads over cores (``-n``) and over CI jobs (``--shard K/N``).
Not named ``test_*.py``: ``pytest conformance/`` (the kit's checks) does not collect it. Each test writes
its program, judges it (:func:`conformance.zoo.judging.judge_program`), appends its outcome to the journal
and fails when app mode rejects the program, with the first failing line and the command that replays it.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

PLAN_VARIABLE = "CONFORMANCE_ZOO_PLAN"


def _plan() -> dict:
    path = os.environ.get(PLAN_VARIABLE)
    if not path:
        raise pytest.UsageError(f"${PLAN_VARIABLE} is not set: run the zoo with `python -m conformance zoo`, which "
                                "writes the plan this file reads")
    return json.loads(Path(path).read_text(encoding="utf-8"))


def pytest_generate_tests(metafunc):
    from conformance.zoo.models import Model

    if "pair" in metafunc.fixturenames:
        metafunc.parametrize("pair", [pytest.param((model, style), id=f"{Model(model).name}--{style}")
                                      for model, style in _plan()["pairs"]])
    if "injected" in metafunc.fixturenames:
        metafunc.parametrize("injected", [pytest.param((model, style, mistake), id=f"{Model(model).name}--{style}--{mistake}")
                                          for model, style, mistake in _plan().get("wrong", [])])


def _keep(plan: dict, outcome) -> None:
    """Append ``outcome`` to this process's journal file (one a process: no interleaved lines)."""
    from conformance.files import write_atomically

    journal = Path(plan["journal"]).with_suffix(f".{os.getpid()}.jsonl")
    previous = journal.read_bytes() if journal.exists() else b""
    write_atomically(journal, previous + (outcome.line() + "\n").encode("utf-8"))


def test_zoo(pair):
    """A right program drawing one model of pybullet_data in one style passes app mode."""
    from conformance.zoo import judging
    from conformance.zoo.models import Model
    from conformance.zoo.styles import STYLES

    plan = _plan()
    model, style = Model(pair[0]), STYLES[pair[1]]
    path = judging.write_program(model, style, plan["backend"], Path(plan["programs"]))
    outcome = judging.judge_program(path, model, style, plan["backend"], ticks=plan["ticks"],
                                    perturbed=plan["perturbed"])
    _keep(plan, outcome)
    if outcome.outcome == "error":
        pytest.fail(f"the kit could not judge {path}: {outcome.first}", pytrace=False)
    if outcome.outcome != "accepted":
        pytest.fail(f"app mode rejected a right program, {path}: {outcome.first}\n"
                    f"diagnoses: {', '.join(outcome.diagnoses) or 'none'}\nreproduce: {outcome.reproduce}", pytrace=False)


def test_zoo_wrong(injected):
    """The same program with one mistake of :mod:`conformance.zoo.mistakes` made fails app mode, unless the
    mistake changes nothing the model shows (measured against the right program's drawing)."""
    from conformance.zoo import judging
    from conformance.zoo.models import Model
    from conformance.zoo.styles import STYLES

    plan = _plan()
    model, style, mistake = Model(injected[0]), STYLES[injected[1]], injected[2]
    right = judging.write_program(model, style, plan["backend"], Path(plan["programs"]))
    wrong = judging.write_program(model, style, plan["backend"], Path(plan["programs"]), mistake)
    outcome = judging.judge_wrong(wrong, right, model, style, plan["backend"], mistake, ticks=plan["ticks"])
    _keep(plan, outcome)
    if outcome.outcome == "error":
        pytest.fail(f"the kit could not judge {wrong}: {outcome.first}", pytrace=False)
    if outcome.outcome == "missed":
        pytest.fail(f"app mode accepted {wrong}, whose drawing is up to {outcome.shown:.3g} m from the right "
                    f"program's ({right})", pytrace=False)
