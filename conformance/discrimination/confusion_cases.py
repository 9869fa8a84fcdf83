"""The cases of the confusion matrix (:mod:`conformance.discrimination.confusion`), gathered from each corpus:
wrong syncs run as ``pytest --sync … -x`` runs them, wrong example apps judged as ``app`` judges them, and the
zoo's journal of injected mistakes read as it stands."""

from __future__ import annotations

import inspect
from pathlib import Path

from conformance.discrimination.confusion import Case
from conformance.errors import ConformanceError

__all__ = ["app_cases", "expected_of", "sync_cases", "zoo_cases"]


def expected_of(spec: str) -> str:
    """The mistake a wrong sync makes, as its docstring's ``Diagnosis: NAME`` line states it (a name of the sync
    checks' catalogue, :mod:`conformance.judge.diagnosis`, or ``-`` for a mistake outside it)."""
    from conformance.judge import diagnosis
    from conformance.sync import load

    names = {*diagnosis.MISTAKES, *diagnosis.SOFT_WORDS, *diagnosis.NORMAL_MISTAKES, "-"}
    doc = inspect.getdoc(load(spec).factory) or ""
    stated = [line.partition(":")[2].strip() for line in doc.splitlines() if line.strip().startswith("Diagnosis:")]
    if len(stated) != 1 or stated[0] not in names:
        raise ConformanceError(f"{spec}: its docstring states the diagnosis {stated or 'nowhere'}, but should have one "
                               f"line 'Diagnosis: NAME', NAME one of {', '.join(sorted(names))} ('-': a mistake the "
                               "catalogue does not hold, which must get no diagnosis)")
    return stated[0]


def sync_cases(specs, *, pytest_args=(), jobs: int | None = None, env=None) -> list[Case]:
    """Each wrong sync of ``specs`` run to its first failure; the case of each the kit rejected."""
    from conformance.discrimination import verdicts
    from conformance.judge.diagnosis import name_of

    expected = {spec: expected_of(spec) for spec in specs}  # every label read before the first (slow) run
    cases = []
    for outcome in verdicts.check_all(list(specs), stop_at_first=True, pytest_args=list(pytest_args), jobs=jobs, env=env):
        if not outcome.failed:
            continue
        first = outcome.failed[0]
        named = name_of(first.get("diagnosis", "")) if first.get("diagnosis") else ""
        cases.append(Case("syncs", outcome.spec, expected[outcome.spec], named,
                          where=f"{first['check']} [{first.get('scene')}]"))
    return cases


def app_cases(paths, *, timeout: float | None = None) -> list[Case]:
    """Each wrong example app of ``paths`` judged as ``app`` judges it (no perturbed runs unless its EXPECT line
    needs them); the case of each the kit rejected, named by the line its report leads with."""
    from conformance.apps import examples
    from conformance.apps.verdict import lead

    cases = []
    for path in paths:
        expected = examples.expectation(path)
        if expected.passes or expected.diagnosis is None:  # a right app, or one whose EXPECT leaves the name open
            continue
        outcome = examples.judge_example(path, perturbed=3 if expected.check == "perturbed" else 0, timeout=timeout)
        if outcome.passed:
            continue
        named = [d for diagnoses in outcome.failed.values() for d in diagnoses]
        first = lead(named)
        where = next((check for check, diagnoses in outcome.failed.items() if first in diagnoses), next(iter(outcome.failed)))
        cases.append(Case("apps", Path(path).as_posix(), expected.diagnosis, first, where=where,
                          also=[d for d in dict.fromkeys(named) if d != first]))
    return cases


def zoo_cases(directory) -> list[Case]:
    """The zoo's rejected wrong programs of one FURY's results ``directory``, as its journal holds them."""
    from conformance.apps.verdict import lead
    from conformance.zoo import judging
    from conformance.zoo.mistakes import MISTAKES

    journal = sorted((Path(directory) / "journal").glob("*.jsonl"))
    if not journal:
        raise ConformanceError(f"{directory}: no zoo journal in it (journal/*.jsonl); `python -m conformance zoo "
                               "--mistakes all` writes one under conformance-results/zoo/BACKEND")
    cases = []
    for o in judging.load_journal(journal):
        if o.outcome != "rejected" or o.mistake not in MISTAKES:
            continue
        first = lead(o.diagnoses)
        cases.append(Case("zoo", f"{o.model} {o.style} {o.mistake}", MISTAKES[o.mistake].diagnosis or "-", first,
                          where=o.failed[0] if o.failed else "", also=[d for d in o.diagnoses if d != first]))
    return cases
