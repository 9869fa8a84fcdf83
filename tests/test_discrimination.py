"""The kit's proof that it discriminates: it fails every deliberately wrong sync and passes every right one.

Each implementation is checked end to end, the way a user runs the kit and the way the README's
kill-rate table is made (``python -m conformance kill-rate``, :mod:`conformance.discrimination.verdicts`)::

    python -m pytest --pyargs conformance -m sync -q --sync wrong_syncs:<Name> --hypothesis-profile triage -x

in its own process (``tests/`` on ``PYTHONPATH``). A wrong one must make pytest exit 1 (checks
failed; not 2, 3 or 4, which are errors) with a failure that names the scene and frame
(``[scene(params), frame N, …]``); a right one must make the same command without ``-x`` exit 0.
The ``triage`` profile is derandomized, so every run of this file tries the same examples.

The runs start with the session, one per core at a time (``background``). They run in pytest's own
process (``--conformance-isolation none``): the kit's own syncs do not crash, and a process of
pytest-xdist's for each of the 29 runs cost 2.5 s of CPU more a run (measured: ``wrong_syncs:OneStepLate``
with ``-x``, 5.6 s against 3.2 s); ``tests/test_crashes.py`` shows the isolation a user's sync gets.
"""

from __future__ import annotations

import inspect
import os
import re
from pathlib import Path

import pytest

import background
import confusion_records
import order_syncs
import right_syncs
import wrong_syncs
from conformance import scenes
from conformance.discrimination import confusion_cases, verdicts
from conformance.judge import diagnosis

TESTS = Path(__file__).resolve().parent
#: The order-dependent mistakes pass every check but the sync-order machine's (``tests/test_order_checks.py``).
WRONG = verdicts.implementations("wrong_syncs") + verdicts.implementations("order_syncs")
RIGHT = verdicts.implementations("right_syncs")

#: How the kit's failure messages name where it went wrong: ``[scene(params), frame N`` or ``[scene, frame N``.
WHERE = re.compile(r"\[(?P<scene>[A-Za-z_][A-Za-z0-9_]*)(?:\(.*?\))?, frame (?P<frame>\d+)")


def _describe(outcome: verdicts.Outcome, stop_at_first: bool) -> str:
    failures = "\n".join(f"  {r['check']} [{r['scene']}]: {r['message'][:400]}" for r in outcome.failed[:3])
    argv = verdicts.command(outcome.spec, stop_at_first=stop_at_first, pytest_args=background.OWN_SYNCS)
    return (f"`PYTHONPATH=tests {' '.join(argv[1:])}` exited {outcome.exitstatus}; "
            f"{len(outcome.failed)} checks failed{':' if failures else '.'}\n{failures}\n{outcome.stderr[-800:]}")


def _env() -> dict[str, str]:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(TESTS), *filter(None, env.get("PYTHONPATH", "").split(os.pathsep))])
    env.pop("CONFORMANCE_SYNC", None)
    return env


def _run(spec: str, stop_at_first: bool):
    """The run of ``spec`` (key and callable for :mod:`background`)."""
    return f"discrimination:{spec}", lambda: verdicts.check(spec, stop_at_first=stop_at_first, env=_env(),
                                                            pytest_args=background.OWN_SYNCS)


def background_runs(items) -> dict:
    """Every selected run, to start with the session: a right sync runs every check, so it goes first."""
    runs = {}
    for item in items:
        spec = getattr(item, "callspec", None) and item.callspec.params.get("spec")
        if spec:
            wrong = item.originalname == "test_kit_fails_a_wrong_sync"
            key, call = _run(spec, stop_at_first=wrong)
            runs[key] = (0 if wrong else 1, call)
    return runs


@pytest.mark.parametrize("spec", [pytest.param(s, id=s.partition(":")[2]) for s in WRONG])
def test_kit_fails_a_wrong_sync(spec):
    outcome = background.result(*_run(spec, stop_at_first=True))
    assert outcome.exitstatus == pytest.ExitCode.TESTS_FAILED and outcome.failed, (
        f"the kit should fail the wrong sync {spec} (exit 1), but {_describe(outcome, True)}")
    where = [m for r in outcome.failed for m in WHERE.finditer(r["message"]) if m["scene"] in scenes.names()]
    assert where, f"the failure of {spec} does not name a scene and frame as '[scene(params), frame N': {_describe(outcome, True)}"
    # Issue 48: the mistake the first failure names, held to the committed confusion record
    first = outcome.failed[0]
    confusion_records.assert_named_no_worse("syncs", spec, actual=diagnosis.name_of(first.get("diagnosis") or ""),
                                            expected=confusion_cases.expected_of(spec),
                                            where=f"{first['check']} [{first.get('scene')}]")


@pytest.mark.parametrize("spec", [pytest.param(s, id=s.partition(":")[2]) for s in RIGHT])
def test_kit_passes_a_right_sync(spec):
    outcome = background.result(*_run(spec, stop_at_first=False))
    assert outcome.exitstatus == pytest.ExitCode.OK, f"the kit should pass the right sync {spec}, but {_describe(outcome, False)}"


def test_every_wrong_and_right_implementation_is_checked():
    """A new public class or function in ``wrong_syncs``, ``order_syncs`` or ``right_syncs`` is in its
    ``__all__``, so it is checked here and counted in the kill rate; each says what it is."""
    for module, minimum, word in ((wrong_syncs, 10, "Wrong: "), (order_syncs, 3, "Wrong: "), (right_syncs, 3, "Right: ")):
        public = {n for n, o in vars(module).items() if (inspect.isclass(o) or inspect.isfunction(o))
                  and o.__module__ == module.__name__ and not n.startswith("_")}
        listed = set(module.__all__)
        assert public <= listed, f"{module.__name__} defines {sorted(public - listed)}, missing from its __all__"
        assert len(listed) >= minimum
        for name in listed:
            doc = inspect.getdoc(getattr(module, name)) or ""
            assert doc.startswith(word), f"{module.__name__}.{name}'s docstring should start {word!r}<what it is>"
