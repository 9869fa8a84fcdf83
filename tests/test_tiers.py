"""CI's fast tier keeps every guarantee (issue 31, point 3; docs/numbers.md, "Tiers").

``./kit test`` (what CI runs) leaves out the tests marked ``full``; ``./kit test --full`` runs them too. A
``full`` mark says why its test is not in CI, and it may never land on a test that carries one of CI's
guarantees: the kill rate of every wrong and right sync and example app, the mutant sample, the README's
examples, the random-draw slice, the zoo's slice, the CI templates. These tests read the marks as pytest does (module ``pytestmark`` and
each function's own), so moving a guarantee out of CI fails here, naming it.
"""

from __future__ import annotations

import importlib
from pathlib import Path

import pytest

TESTS = Path(__file__).resolve().parent
#: The modules that carry CI's guarantees: none of their tests may be in the full tier.
GUARANTEES = ["test_discrimination", "test_examples", "test_mutants", "test_readme_example", "test_random_draws",
              "test_tiers", "test_zoo", "test_ci_templates"]


def _marks(obj) -> list:
    marks = getattr(obj, "pytestmark", [])
    return marks if isinstance(marks, list) else [marks]


def full_marks(module) -> dict[str, pytest.Mark]:
    """Where ``module`` puts a ``full`` mark: ``"<module>"`` for the whole module, else each test's name,
    or ``name[id]`` for one ``pytest.param`` of it."""
    found = {"<module>": m for m in _marks(module) if m.name == "full"}
    for name, obj in vars(module).items():
        if not (name.startswith("test") and callable(obj)):
            continue
        for mark in _marks(obj):
            if mark.name == "full":
                found[name] = mark
            elif mark.name == "parametrize":
                for i, value in enumerate(mark.args[1] if len(mark.args) > 1 else mark.kwargs.get("argvalues", [])):
                    for m in getattr(value, "marks", ()):
                        if m.name == "full":
                            found[f"{name}[{getattr(value, 'id', None) or i}]"] = m
    return found


def assert_guarantees_stay_fast(modules) -> None:
    __tracebackhide__ = True
    for module in modules:
        marked = full_marks(module)
        assert not marked, (f"{module.__name__} carries one of CI's guarantees, but {sorted(marked)} "
                            "is marked `full`: CI would no longer run it")


def assert_full_marks_give_a_reason(modules) -> None:
    __tracebackhide__ = True
    for module in modules:
        for where, mark in full_marks(module).items():
            reason = " ".join(map(str, mark.args)) + str(mark.kwargs.get("reason", ""))
            assert len(reason) >= 20, (f"{module.__name__}::{where} is marked `full` with reason {reason!r}, but "
                                       "should say why it is not in CI's fast tier")


def _test_modules():
    return [importlib.import_module(p.stem) for p in sorted(TESTS.glob("test_*.py"))]


def test_no_guarantee_is_in_the_full_tier():
    assert_guarantees_stay_fast([importlib.import_module(name) for name in GUARANTEES])


def test_every_full_mark_says_why():
    modules = _test_modules()
    assert_full_marks_give_a_reason(modules)
    assert any(full_marks(m) for m in modules), "no test is in the full tier: the fast tier is the whole suite"


def test_a_guarantee_marked_full_is_named(tmp_path, monkeypatch):
    (tmp_path / "made_up_guarantee.py").write_text(
        "import pytest\n\n@pytest.mark.full('slow and not a guarantee, or so someone thought')\n"
        "def test_kill_rate():\n    pass\n", encoding="utf-8")
    (tmp_path / "made_up_param.py").write_text(
        "import pytest\n\n@pytest.mark.parametrize('n', [1, pytest.param(2, id='two', marks=pytest.mark.full('x' * 30))])\n"
        "def test_kill_rate(n):\n    pass\n", encoding="utf-8")
    (tmp_path / "made_up_reasonless.py").write_text(
        "import pytest\n\npytestmark = pytest.mark.full('slow')\n\ndef test_a():\n    pass\n", encoding="utf-8")
    monkeypatch.syspath_prepend(str(tmp_path))
    guarantee, param, reasonless = (importlib.import_module(n) for n in
                                    ("made_up_guarantee", "made_up_param", "made_up_reasonless"))
    with pytest.raises(AssertionError, match=r"made_up_guarantee carries .*\['test_kill_rate'\] is marked `full`"):
        assert_guarantees_stay_fast([guarantee])
    with pytest.raises(AssertionError, match=r"made_up_param carries .*\['test_kill_rate\[two\]'\] is marked `full`"):
        assert_guarantees_stay_fast([param])
    with pytest.raises(AssertionError, match=r"made_up_reasonless::<module> is marked `full` with reason 'slow'"):
        assert_full_marks_give_a_reason([reasonless])


def test_the_fast_tier_leaves_out_full_tests_and_says_so(pytester):
    pytester.makeconftest("pytest_plugins = ['tiers']")
    pytester.makepyfile(test_some="import pytest\n\n@pytest.mark.full('a slow test of robustness, here')\n"
                                  "def test_slow():\n    pass\n\ndef test_quick():\n    pass\n")
    fast = pytester.runpytest("-p", "no:randomly", "-v")
    fast.assert_outcomes(passed=1, deselected=1)
    fast.stdout.fnmatch_lines(["tier: fast*--full*", "*test_quick PASSED*"])
    full = pytester.runpytest("-p", "no:randomly", "--full")
    full.assert_outcomes(passed=2)
    asked = pytester.runpytest("-p", "no:randomly", "test_some.py::test_slow")  # named by its node id: it runs
    asked.assert_outcomes(passed=1)


def test_a_fury_free_test_runs_in_one_suite_when_both_run_at_once(pytester, monkeypatch):
    """``./kit test --backend all`` runs the two suites at once and sets ``KIT_SUITE_BESIDE=vtk`` in FURY 2's:
    a test whose verdict cannot depend on the FURY runs in FURY 0.12's suite only, and the header says so."""
    import tiers

    pytester.makeconftest("pytest_plugins = ['tiers']")
    pytester.makepyfile(test_some="import pytest\n\n@pytest.mark.fury_free('a bash script alone, here')\n"
                                  "def test_bash():\n    pass\n\ndef test_fury():\n    pass\n")
    monkeypatch.delenv(tiers.BESIDE, raising=False)
    alone = pytester.runpytest("-p", "no:randomly")
    alone.assert_outcomes(passed=2)
    monkeypatch.setenv(tiers.BESIDE, "vtk")
    beside = pytester.runpytest("-p", "no:randomly", "-v")
    beside.assert_outcomes(passed=1, deselected=1)
    beside.stdout.fnmatch_lines(["*`fury_free` are left to the vtk suite*", "*test_fury PASSED*"])
