"""The pytest plugin (registered through the ``pytest11`` entry point): options, header, fixtures, verdicts.

Options live under one group, each mirrored by an ini setting:

* ``--sync SPEC`` / ``conformance_sync``: the implementation under test, a short name or
  ``module:attribute``; ``$CONFORMANCE_SYNC`` when neither is given; ``reference`` by default.

Loading this plugin is cheap: it imports pybullet, VTK and the sync only when a conformance check
is collected, so it stays out of the way of unrelated test suites in the same environment.
"""

from __future__ import annotations

from collections import defaultdict

import pytest

from conformance import profiles

SYNC_OPTION = "--sync"
_SYNC_KEY = pytest.StashKey["object"]()
_VERDICT_KEY = pytest.StashKey[dict]()


def pytest_addoption(parser: pytest.Parser) -> None:
    group = parser.getgroup("conformance", "FURY–pyBullet conformance")
    group.addoption(
        SYNC_OPTION,
        dest="conformance_sync",
        metavar="SPEC",
        default=None,
        help="sync implementation under test: a short name (reference, guide, guide-actor, guide-vertex, "
        "guide-joint) or module:attribute. Default: ini conformance_sync, else $CONFORMANCE_SYNC, else reference.",
    )
    parser.addini("conformance_sync", "default for --sync", default=None)


def _sync_spec(config: pytest.Config) -> str:
    from conformance.sync import resolve_spec

    return resolve_spec(config.getoption("conformance_sync") or config.getini("conformance_sync"))


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line("markers", "scene(name): the reference scene a conformance check runs on")
    config.stash[_VERDICT_KEY] = defaultdict(lambda: defaultdict(list))


def pytest_unconfigure(config: pytest.Config) -> None:
    from conformance.display import stop_display

    stop_display()


def pytest_report_header(config: pytest.Config) -> list[str]:
    import importlib.metadata as md

    versions = []
    for dist in ("pybullet", "fury", "vtk", "numpy", "hypothesis"):
        try:
            versions.append(f"{dist} {md.version(dist)}")
        except md.PackageNotFoundError:
            versions.append(f"{dist} missing")
    return [
        f"conformance: sync {_sync_spec(config)!r}; {profiles.describe()}",
        "conformance: " + ", ".join(versions),
    ]


def pytest_collection_modifyitems(session: pytest.Session, config: pytest.Config, items) -> None:
    """Load the sync under test once, before any check runs, if any collected check needs it."""
    if not any("sync_implementation" in getattr(item, "fixturenames", ()) for item in items):
        return
    from conformance.errors import SyncError
    from conformance.sync import load

    try:
        config.stash[_SYNC_KEY] = load(_sync_spec(config))
    except SyncError as err:
        raise pytest.UsageError(str(err)) from None


@pytest.fixture(scope="session")
def sync_implementation(request: pytest.FixtureRequest):
    """The loaded sync implementation under test (see ``conformance.sync``)."""
    try:
        return request.config.stash[_SYNC_KEY]
    except KeyError:  # collected in an unusual way (e.g. a plugin added items late): load now
        from conformance.sync import load

        implementation = load(_sync_spec(request.config))
        request.config.stash[_SYNC_KEY] = implementation
        return implementation


@pytest.hookimpl(wrapper=True)
def pytest_runtest_makereport(item: pytest.Item, call):
    report = yield
    marker = item.get_closest_marker("scene")
    if marker is not None and (report.when == "call" or report.outcome != "passed"):
        item.config.stash[_VERDICT_KEY][marker.args[0]][report.outcome].append(item.name)
    return report


def pytest_terminal_summary(terminalreporter, exitstatus, config: pytest.Config) -> None:
    verdicts = config.stash.get(_VERDICT_KEY, None)
    if not verdicts:
        return
    tr = terminalreporter
    tr.section(f"conformance verdict per scene (sync {_sync_spec(config)!r})")
    width = max(len(name) for name in verdicts)
    for scene, outcomes in verdicts.items():
        failed = len(outcomes.get("failed", []))
        passed = len(outcomes.get("passed", []))
        skipped = len(outcomes.get("skipped", []))
        verdict = "FAIL" if failed else ("PASS" if passed else "SKIP")
        detail = f"{passed} passed" + (f", {failed} failed" if failed else "") + (f", {skipped} skipped" if skipped else "")
        tr.write_line(f"{verdict:4}  {scene:<{width}}  {detail}", red=bool(failed), green=not failed and bool(passed))
