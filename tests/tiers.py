"""The kit's own tests in two tiers (issue 31, point 3; docs/numbers.md, "Tiers"): CI's fast tier, what
``./kit test`` runs, and the full tier, ``./kit test --full``, which adds the tests marked ``full``: slow
tests of robustness, timing or tooling that carry none of CI's guarantees (``tests/test_tiers.py`` holds
the marks to that). A pytest plugin, loaded by ``conftest.py``."""

from __future__ import annotations

import pytest

FAST = "tier: fast, CI's (tests marked `full` are deselected; `./kit test --full` runs them too)"
FULL = "tier: full (every test)"


def pytest_addoption(parser: pytest.Parser) -> None:
    parser.addoption("--full", action="store_true", default=False,
                     help="run the full tier: the kit's tests marked `full` too (slow tests of robustness, timing "
                          "and tooling; docs/numbers.md, 'Tiers'). CI runs the fast tier.")


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line(
        "markers", "full(reason): in the full tier only (`./kit test --full`), with why it is not in CI's fast "
                   "tier: a slow test of robustness, timing or tooling that carries none of CI's guarantees")


@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Without ``--full``, the tests marked ``full`` are deselected, as ``-m 'not full'`` would (a user's own
    ``-m`` still applies), but for a test named by its node id (``file.py::test_name``): asked for, it runs."""
    if config.getoption("full"):
        return
    named = [arg.replace("\\", "/") for arg in config.args if "::" in arg]
    left_out = [item for item in items if item.get_closest_marker("full") and not any(_names(n, item.nodeid) for n in named)]
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
    return [FULL if config.getoption("full") else FAST]
