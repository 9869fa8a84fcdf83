"""The kit's own tests in two tiers (issue 31, point 3; docs/numbers.md, "Tiers"): CI's fast tier, what
``./kit test`` runs, and the full tier, ``./kit test --full``, which adds the tests marked ``full``: slow
tests of robustness, timing or tooling that carry none of CI's guarantees (``tests/test_tiers.py`` holds
the marks to that). A pytest plugin, loaded by ``conftest.py``."""

from __future__ import annotations

import os

import pytest

FAST = "tier: fast, CI's (tests marked `full` are deselected; `./kit test --full` runs them too)"
FULL = "tier: full (every test)"
#: Set by ``./kit test --backend all`` (CI) in the FURY 2 suite to the backend whose suite runs beside it: the
#: tests marked ``fury_free`` (their verdict cannot depend on the FURY: a bash script, the kit's imports, pyBullet
#: alone) run in that suite only, not twice. FURY 2's is the longer suite, the one CI waits for.
BESIDE = "KIT_SUITE_BESIDE"


def pytest_addoption(parser: pytest.Parser) -> None:
    parser.addoption("--full", action="store_true", default=False,
                     help="run the full tier: the kit's tests marked `full` too (slow tests of robustness, timing "
                          "and tooling; docs/numbers.md, 'Tiers'). CI runs the fast tier.")


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line(
        "markers", "fury_free(reason): touches no FURY, so its verdict is the same in both environments; when both "
                   f"suites run at once (`./kit test --backend all`, ${BESIDE} set) only the other suite runs it")
    config.addinivalue_line(
        "markers", "full(reason): in the full tier only (`./kit test --full`), with why it is not in CI's fast "
                   "tier: a slow test of robustness, timing or tooling that carries none of CI's guarantees")


@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Without ``--full``, the tests marked ``full`` are deselected, as ``-m 'not full'`` would (a user's own
    ``-m`` still applies), and with :data:`BESIDE` set the tests marked ``fury_free``; but for a test named by
    its node id (``file.py::test_name``): asked for, it runs."""
    named = [arg.replace("\\", "/") for arg in config.args if "::" in arg]
    beside = os.environ.get(BESIDE)
    left_out = [item for item in items if not any(_names(n, item.nodeid) for n in named)
                and ((item.get_closest_marker("full") and not config.getoption("full"))
                     or (beside and item.get_closest_marker("fury_free")))]
    if left_out:
        config.hook.pytest_deselected(items=left_out)
        gone = set(map(id, left_out))
        items[:] = [item for item in items if id(item) not in gone]


def _names(arg: str, nodeid: str) -> bool:
    """Whether the command-line argument ``arg`` names the test ``nodeid`` (from any directory; without
    a ``[param]``, every parameter of it)."""
    test = nodeid if "[" in arg else nodeid.split("[")[0]
    return arg == test or arg.endswith("/" + test) or test.endswith("/" + arg)


def pytest_report_header(config: pytest.Config) -> list[str]:
    beside = os.environ.get(BESIDE)
    return [FULL if config.getoption("full") else FAST] + (
        [f"tests marked `fury_free` are left to the {beside} suite, which runs beside this one (${BESIDE})"] if beside else [])
