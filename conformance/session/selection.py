"""Which checks a run executes: shards across CI jobs, and runs that checked less than asked.

* ``--shard K/N`` (1 <= K <= N) keeps every N-th conformance check starting at the K-th, in
  collection order, and deselects the rest. Collection order is the same in every process, so the
  N shards of one checkout partition its checks: each check runs in exactly one shard. Tests that
  are not conformance checks (no ``scene`` mark and not in the kit's package) are dealt out the
  same way, so ``pytest --shard K/N tests conformance`` splits a whole suite.
* A ``-k`` expression whose every word is looked up in the collected checks: a word that matches
  none of them (``-k "chain or brick_wal"``) is a typo that would otherwise shrink the run silently,
  so the run stops before anything executes, naming the word and what it could have matched.
* A run that was asked to check a sync (``--sync``, ``conformance_sync`` or ``$CONFORMANCE_SYNC``)
  but executed no check that runs a sync ends with exit status 5 (pytest's "no tests ran"), not a
  green verdict about nothing.

Registered by :mod:`conformance.plugin`; no option here has an ini twin, because a shard or a ``-k``
belongs to one invocation, not to a project.
"""

from __future__ import annotations

import re

import pytest

__all__ = ["Selection", "Shard", "add_options", "parse_shard"]

#: The words of a ``-k`` expression that are not names to match.
_OPERATORS = {"and", "or", "not", "True", "False", "None"}
_WORD = re.compile(r"[^\s()]+")
_WORKER_KEY = "conformance_selection_refused"


def add_options(group) -> None:
    group.addoption("--shard", dest="conformance_shard", metavar="K/N", default=None,
                    help="run only the K-th of N equal shares of the selected checks (1 <= K <= N); the N shards "
                    "of a checkout run every check exactly once. For splitting a run across CI jobs")


def parse_shard(text: str) -> tuple[int, int]:
    """``"K/N"`` as ``(K, N)``; refuses anything that is not two whole numbers with 1 <= K <= N."""
    from conformance import validation
    from conformance.errors import BadArgument

    try:
        return validation.shard("--shard", text)
    except BadArgument as err:
        raise pytest.UsageError(str(err)) from None


def _words(expression: str) -> list[str]:
    return [w for w in _WORD.findall(expression) if w not in _OPERATORS]


def _matches(word: str, item: pytest.Item) -> bool:
    # pytest's own matcher for -k words (names of the item and its parents, keywords, marks), so a
    # word is unknown here exactly when pytest's -k would match nothing with it.
    from _pytest.mark import KeywordMatcher

    return KeywordMatcher.from_item(item)(word)


class Shard:
    """Deselects all but one shard; last of the collection hooks, so it splits what -k and -m kept."""

    def __init__(self, k: int, n: int):
        self.k, self.n = k, n

    @pytest.hookimpl(trylast=True)
    def pytest_collection_modifyitems(self, config, items) -> None:
        kept = [item for i, item in enumerate(items) if i % self.n == self.k - 1]
        dropped = [item for i, item in enumerate(items) if i % self.n != self.k - 1]
        if dropped:
            config.hook.pytest_deselected(items=dropped)
        items[:] = kept


class Selection:
    """The plugin object: checks ``-k`` words, counts what ran; registers a :class:`Shard` if asked."""

    def __init__(self, config: pytest.Config, sync_named: bool):
        self.sync_named = sync_named
        self.message = ""  # why a green run is turned red
        self.usage = ""  # why the selection was refused (from an xdist worker)
        shard = config.getoption("conformance_shard")
        if shard is not None:
            config.pluginmanager.register(Shard(*parse_shard(shard)), "conformance-shard")
        self.ran_sync_checks = 0
        self.ran_any = 0

    @pytest.hookimpl(tryfirst=True)
    def pytest_collection_modifyitems(self, session, config, items) -> None:
        # tryfirst: before pytest's own -k deselection, so every word is looked up in everything collected.
        expression = config.getoption("keyword")
        # Only in sessions with conformance checks in them: the plugin stays out of unrelated suites.
        if expression and any(item.get_closest_marker("scene") for item in items):
            unknown = [w for w in _words(expression) if not any(_matches(w, item) for item in items)]
            if unknown:
                from conformance import scenes

                message = (
                    f"-k {expression!r}: {', '.join(repr(w) for w in unknown)} matches none of the {len(items)} "
                    f"collected checks, so this run would silently check less than asked (a typo?). Scenes: "
                    f"{', '.join(scenes.names())}; list checks with --collect-only -q.")
                if not hasattr(config, "workerinput"):
                    raise pytest.UsageError(message)
                # A pytest-xdist worker cannot stop the session; it runs nothing and tells the controller.
                config.workeroutput[_WORKER_KEY] = message
                config.hook.pytest_deselected(items=list(items))
                items[:] = []

    @pytest.hookimpl(optionalhook=True)
    def pytest_testnodedown(self, node, error) -> None:
        message = getattr(node, "workeroutput", {}).get(_WORKER_KEY)
        if message:
            self.usage = message

    def pytest_runtest_logreport(self, report) -> None:
        if report.when == "call" or (report.when == "setup" and report.outcome != "passed"):
            # The kit's package name is among the keywords of its checks, however they were collected.
            if "conformance" in report.keywords:
                self.ran_any += 1
            if "sync" in report.keywords:
                self.ran_sync_checks += 1

    @pytest.hookimpl(trylast=True)
    def pytest_sessionfinish(self, session, exitstatus) -> None:
        if hasattr(session.config, "workerinput"):
            return
        if self.usage:
            session.exitstatus = pytest.ExitCode.USAGE_ERROR
            return
        if exitstatus != 0 or not self.sync_named:
            return
        if self.ran_any and not self.ran_sync_checks:
            self.message = ("the run was asked to check a sync implementation, but none of the checks it executed "
                            "runs one (the selection kept only checks of pybullet or of the kit itself); the green "
                            "result says nothing about the sync. Widen -k/-m, or select them with -m sync.")
            session.exitstatus = pytest.ExitCode.NO_TESTS_COLLECTED

    def pytest_terminal_summary(self, terminalreporter) -> None:
        if self.usage:
            terminalreporter.write_line(f"ERROR: {self.usage}", red=True)
        if self.message:
            terminalreporter.section("conformance: nothing of the sync was checked", red=True)
            terminalreporter.write_line(self.message, red=True)
