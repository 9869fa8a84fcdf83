"""The pytest plugin (registered through the ``pytest11`` entry point): options, header, fixtures, verdicts.

Options live under one group, each mirrored by an ini setting:

* ``--sync SPEC`` / ``conformance_sync``: the implementation under test, a short name or
  ``module:attribute``; ``$CONFORMANCE_SYNC`` when neither is given; ``reference`` by default.
* ``--conformance-sync-timeout SECONDS`` / ``conformance_sync_timeout``: the longest one call into the
  sync may take (default 10 s, 0 for none; :mod:`conformance.sync.time_limit`).
* ``--conformance-isolation auto|process|none`` / ``conformance_isolation``: whether a serial run goes to
  one worker process, so that a sync that crashes the interpreter fails its checks (:mod:`conformance.session.isolation`).
* ``--conformance-size-rtol``, ``--conformance-position-rtol``, ``--conformance-atol``,
  ``--conformance-normal-angle`` (and ``conformance_size_rtol`` … in the ini file): the tolerances
  of :mod:`conformance.judge.tolerances`.
* ``--conformance-report PATH`` / ``conformance_report``: write every check's outcome, scene and
  worst measured error as JSON (what ``python -m conformance verdicts`` reads).
* ``--conformance-summary PATH`` / ``conformance_summary``: write the run's Markdown summary there
  (:mod:`conformance.reports.summary`); it is added to ``$GITHUB_STEP_SUMMARY`` too, when that is set.
* Pictures (:mod:`conformance.checks.image_options` reads and validates them):
  ``--conformance-golden-dir DIR`` / ``conformance_golden_dir`` (default: each scene's own goldens: the kit's, or golden/<backend>/ beside your scene file),
  ``--conformance-image-tolerance auto|same-renderer|other-renderer`` / ``conformance_image_tolerance``,
  ``--conformance-results DIR`` / ``conformance_results`` (failure pictures, records and the HTML report;
  default ``conformance-results``), ``--conformance-keep-passing`` / ``conformance_keep_passing`` (keep the
  pictures of passing image checks too), and ``--regen-golden`` (make the selected scenes' goldens anew
  before checking them; never done without it).

Loading this plugin is cheap: it imports pybullet, the renderer and the sync only when a conformance check
is collected, so it stays out of the way of unrelated test suites in the same environment.
"""

from __future__ import annotations

import dataclasses
from collections import defaultdict

import pytest

from conformance.checks import profiles

SYNC_OPTION = "--sync"
_SYNC_KEY = pytest.StashKey["object"]()
_VERDICT_KEY = pytest.StashKey[dict]()
_RECORDS_KEY = pytest.StashKey[list]()
#: How many checks of each scene the session selected (not known in pytest-xdist's controller, which collects nothing).
_SELECTED_KEY = pytest.StashKey[dict]()
#: per scene, how many of its checks -k or -m left out: its PASS then covers the selected ones only
_DESELECTED_KEY = pytest.StashKey[dict]()
#: per scene, why its checks were left out (``-m 'not soft'``, ``-k 'chain'``, ``--shard 1/2``) and how many each
_LEFT_OUT_KEY = pytest.StashKey[dict]()
#: The name under which each check's record rides on its report (``report.user_properties``).
_RECORD_PROPERTY = "conformance_record"
#: Whether a check of the kit reported in this session (else it writes no summary: an unrelated suite's run).
_KIT_RAN_KEY = pytest.StashKey[bool]()


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
    group.addoption("--conformance-sync-timeout", dest="conformance_sync_timeout", default=None, metavar="SECONDS",
                    help="longest one call into the sync may take before its check fails with where it was "
                    "(default 10; 0: no limit); the kit's own stepping and rendering are not limited")
    parser.addini("conformance_sync_timeout", "default for --conformance-sync-timeout", default=None)
    group.addoption("--conformance-isolation", dest="conformance_isolation", default=None, metavar="MODE",
                    help="where the checks run, so that a sync that crashes the interpreter fails its checks and "
                    "the run goes on: auto (default: a serial run of a sync that is not the kit's own runs in one "
                    "pytest-xdist worker), process (any sync), none (pytest's own process)")
    parser.addini("conformance_isolation", "default for --conformance-isolation", default=None)
    for name, help_text in _TOLERANCE_OPTIONS.items():
        # No type=float: conformance.validation reads the text, so a bad number, NaN or inf is refused
        # with the same sentence as in the ini file.
        group.addoption(f"--conformance-{name.replace('_', '-')}", dest=f"conformance_{name}",
                        default=None, metavar="X", help=help_text)
        parser.addini(f"conformance_{name}", help_text, default=None)
    group.addoption("--conformance-report", dest="conformance_report", metavar="PATH", default=None,
                    help="write each check's outcome, scene and worst error as JSON to PATH")
    parser.addini("conformance_report", "default for --conformance-report", default=None)
    group.addoption("--conformance-summary", dest="conformance_summary", metavar="PATH", default=None,
                    help="write the run's summary as Markdown to PATH: each scene's verdict, the first failure with its "
                    "diagnosis and reproduce line, every failing check, links to pictures (added to "
                    "$GITHUB_STEP_SUMMARY as well, when set)")
    parser.addini("conformance_summary", "default for --conformance-summary", default=None)
    group.addoption("--conformance-survey", dest="conformance_survey", action="store_true", default=None,
                    help="survey mode: a check notes every failure and runs every frame, then fails with the first "
                    "failure and every kind that failed with its worst figure (what 'verdicts' uses; default: stop "
                    "at the first failing frame)")
    parser.addini("conformance_survey", "default for --conformance-survey", type="bool", default=False)
    group.addoption("--conformance-app", dest="conformance_app", action="append", default=None, metavar="PATH",
                    help="an application script to check as it is (repeatable; replaces the ini conformance_apps)")
    parser.addini("conformance_apps", "application scripts to check as they are: globs relative to the rootdir, "
                  "{backend} standing for vtk or pygfx", type="linelist", default=[])
    group.addoption("--conformance-app-ticks", dest="conformance_app_ticks", default=None, metavar="N",
                    help="ticks of each app's own run (default 120)")
    parser.addini("conformance_app_ticks", "default for --conformance-app-ticks", default=None)
    group.addoption("--conformance-scenes", "--scenes", dest="conformance_scenes", action="append", default=None, metavar="SOURCE",
                    help="a .py file or module of your own scenes (SceneSpec objects), checked beside the kit's "
                    "(also spelled --scenes, as python -m conformance spells it); repeatable, added to the ini "
                    "conformance_scenes and $CONFORMANCE_SCENES")
    parser.addini("conformance_scenes", "your own scene sources (.py files relative to the ini file, or modules), "
                  "one per line", type="linelist", default=[])
    from conformance.checks import image_options

    image_options.add_options(group, parser)
    from conformance.session import selection

    selection.add_options(group)


_TOLERANCE_OPTIONS = {
    "size_rtol": "vertex tolerance per metre of body size (default 1e-5)",
    "position_rtol": "vertex tolerance per metre of distance from the origin (default 2.4e-7)",
    "atol": "absolute vertex tolerance in metres (default 1e-9)",
    "normal_angle": "largest angle in radians between a drawn and an expected vertex normal (default 1e-4)",
}


def _option(config: pytest.Config, name: str):
    """Option ``conformance_NAME`` (command line, else ini), checked by :mod:`conformance.validation`;
    ``None`` when not given. A refused value is a usage error naming the option, value and fix."""
    from conformance import validation
    from conformance.errors import BadArgument

    try:
        return validation.plugin_option(config, name)
    except BadArgument as err:
        raise pytest.UsageError(str(err)) from None


def tolerance_from(config: pytest.Config):
    from conformance.judge.tolerances import DEFAULT

    values = {name: value for name in _TOLERANCE_OPTIONS if (value := _option(config, name)) is not None}
    return dataclasses.replace(DEFAULT, **values)


def _sync_spec(config: pytest.Config) -> str:
    from conformance.errors import BadArgument
    from conformance.validation import resolve_sync

    try:  # an empty --sync, ini value or $CONFORMANCE_SYNC is refused, never read as "the default"
        return resolve_sync(config.getoption("conformance_sync"), config.getini("conformance_sync"))
    except BadArgument as err:
        raise pytest.UsageError(str(err)) from None


def app_paths(config: pytest.Config) -> list:
    """The apps to check (``--conformance-app``, else the ini ``conformance_apps``), as paths; a pattern that
    matches nothing, or a path that is not a file, is a usage error naming it."""
    from pathlib import Path

    given = config.getoption("conformance_app")
    if given:
        missing = [g for g in given if not Path(g).is_file()]
        if missing:
            raise pytest.UsageError(f"--conformance-app={missing[0]!r}: no such file; give the path of an app's script")
        return [Path(g).resolve() for g in given]
    patterns = config.getini("conformance_apps")
    if not patterns:
        return []
    from conformance import backends
    from conformance.apps.mapping import SUFFIX  # an app's mapping beside it is not an app

    found = []
    for pattern in patterns:
        pattern = pattern.replace("{backend}", backends.NAME)
        matches = sorted(p for p in config.rootpath.glob(pattern) if p.is_file() and not p.name.endswith(SUFFIX))
        if not matches:
            raise pytest.UsageError(f"ini conformance_apps: {pattern!r} matches no file under {config.rootpath}")
        found.extend(matches)
    return list(dict.fromkeys(found))


def app_ticks(config: pytest.Config) -> int:
    from conformance import apps, validation
    from conformance.errors import BadArgument

    value = config.getoption("conformance_app_ticks") or config.getini("conformance_app_ticks")
    if not value:
        return apps.DEFAULT_TICKS
    try:
        return validation.whole_number("--conformance-app-ticks", value, low=1, high=validation.MAX_STEPS)
    except BadArgument as err:
        raise pytest.UsageError(str(err)) from None


def load_own_scenes(config: pytest.Config) -> None:
    """Register the user's scenes (``--conformance-scenes``, ini ``conformance_scenes``, ``$CONFORMANCE_SCENES``,
    entry points) before the checks are collected: they are parametrized over the registry at import."""
    from conformance.sync import own_scenes
    from conformance.errors import BadArgument

    try:
        own_scenes.load_all(config.getini("conformance_scenes"),
                            relative_to=config.inipath.parent if config.inipath else config.rootpath)
        own_scenes.load_all(config.getoption("conformance_scenes") or (), environment=False)
    except BadArgument as err:
        raise pytest.UsageError(str(err)) from None


@pytest.hookimpl(wrapper=True)
def pytest_cmdline_main(config: pytest.Config):
    """Before pytest-xdist reads ``-n``: a serial run whose sync may crash goes to one worker process."""
    from conformance.session import isolation

    isolation.arrange(config, _sync_spec(config), _option(config, "isolation") or "auto")
    return (yield)


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line("markers", "scene(name): the reference scene a conformance check runs on")
    load_own_scenes(config)
    _watch_for_crashes(config)
    config.addinivalue_line("markers", "sync: a check that runs the sync implementation under test (added automatically)")
    config.addinivalue_line("markers", "draws: a check whose examples are drawn at random (Hypothesis; added automatically "
                            "to a @given check): what `precision` and the kit's random-draw slice run")
    config.addinivalue_line("markers", "soft: a check of a scene with soft bodies (cloth, soft_ball, jelly; added automatically): "
                            "-m 'not soft' leaves them out, for a program that has no soft bodies")
    # pytest-xdist registers it itself; without xdist installed the kit's grouping of a scene's checks
    # would otherwise warn as an unknown mark in every run.
    config.addinivalue_line("markers", "xdist_group(name): checks pytest-xdist runs in one worker (one scene's)")
    app_paths(config), app_ticks(config)  # a missing app or a bad tick count stops the run before collection
    config.stash[_VERDICT_KEY] = defaultdict(lambda: defaultdict(list))
    # -n keeps pytest-xdist's default scheduling. Grouping a scene's checks on one worker
    # ("loadgroup") would spare a second worker stepping the same scene, but xdist 3.8 applies groups
    # only when --dist loadgroup is on the command line its workers re-read, and its group scheduler
    # stalls after a worker crashes (conformance.session.isolation), so the kit no longer asks for it;
    # --dist loadgroup given by the user still groups by the marks added below.
    config.pluginmanager.register(_Records(config), "conformance-records")
    if not hasattr(config, "workerinput"):
        config.pluginmanager.register(_Summary(), "conformance-summary")
    import os

    from conformance.session import selection
    from conformance.sync import ENV_VAR

    named = bool(config.getoption("conformance_sync") or config.getini("conformance_sync") or ENV_VAR in os.environ)
    config.pluginmanager.register(selection.Selection(config, sync_named=named), "conformance-selection")
    if not hasattr(config, "workerinput"):
        from conformance.checks import image_options

        image_options.from_config(config).start_session()


def _watch_for_crashes(config: pytest.Config) -> None:
    """In pytest-xdist's controller: the crash handler, xdist's restart cap raised to a crash per scene,
    and the sync loaded and the options read once here too, so that a sync that cannot be loaded or a
    bad value is the usual one-paragraph usage error rather than a worker's internal error (workers
    start their journal at ``pytest_sessionstart``)."""
    from conformance.session import isolation

    if hasattr(config, "workerinput"):
        return
    if getattr(config.option, "dist", "no") == "no" or not getattr(config.option, "tx", None):
        return
    from conformance import scenes

    isolation.allow_restarts(config, len(scenes.names()))
    spec = _sync_spec(config)
    seconds = _option(config, "sync_timeout")  # a bad value: the usage error, here, once
    tolerance_from(config)
    config.pluginmanager.register(isolation.Controller(config, spec, _RECORD_PROPERTY, seconds), "conformance-crashes")
    from conformance.implementations import SHORT_NAMES

    if spec not in SHORT_NAMES:
        from conformance.errors import SyncError
        from conformance.sync import load

        try:
            load(spec)
        except SyncError as err:
            raise pytest.UsageError(str(err)) from None


def pytest_sessionstart(session: pytest.Session) -> None:
    if hasattr(session.config, "workerinput"):  # after pytest's own faulthandler set-up, which it replaces
        from conformance.sync import journal

        journal.start_journal(session.config)


def pytest_runtest_logstart(nodeid: str, location) -> None:
    from conformance.sync import journal

    journal.noting(nodeid)


def pytest_unconfigure(config: pytest.Config) -> None:
    from conformance.backends.display import stop_display

    stop_display()


def pytest_report_header(config: pytest.Config) -> list[str]:
    import importlib.metadata as md

    versions = []
    for dist in ("pybullet", "numpy", "hypothesis"):
        try:
            versions.append(f"{dist} {md.version(dist)}")
        except md.PackageNotFoundError:
            versions.append(f"{dist} missing")
    from conformance import backends
    from conformance.checks import image_options
    from conformance.errors import BackendError

    try:
        backend = backends.describe()
    except BackendError as exc:
        backend = f"no backend: {exc}"
    try:
        apps = app_paths(config)
    except pytest.UsageError:
        apps = []  # said once, where the apps are collected
    # The sync is what the scenes' checks run; an app is judged on its own code, whatever --sync says.
    judged = (f"sync {_sync_spec(config)!r} in the scenes' checks; apps (their own code): "
              + ", ".join(p.name for p in apps[:4]) + (f" and {len(apps) - 4} more" if len(apps) > 4 else "")
              if apps else f"sync {_sync_spec(config)!r}")
    return [
        f"conformance: {backend}",
        f"conformance: {judged}; {profiles.describe()}; tolerance {tolerance_from(config).describe()}",
        "conformance: " + ", ".join(versions),
        "conformance: " + image_options.from_config(config).describe(),
    ]


@pytest.hookimpl(tryfirst=True)  # before pytest-xdist's worker names the items by their xdist_group
def pytest_collection_modifyitems(session: pytest.Session, config: pytest.Config, items) -> None:
    """Mark the checks that run the sync under test (``-m sync`` selects them) and load the sync once,
    before any check runs, if any collected check needs it."""
    from conformance.session import ordering

    placeholders = [item for item in items if getattr(item, "callspec", None) is not None
                    and "app" in item.callspec.params and item.callspec.params["app"] is None]
    if placeholders:  # no app configured: the app checks are not collected at all
        items[:] = [item for item in items if item not in placeholders]
        config.hook.pytest_deselected(items=placeholders)
    soft = {}
    for item in items:
        if _is_property(item):
            item.add_marker(pytest.mark.draws)
        marker = item.get_closest_marker("scene")
        if marker is not None and _has_soft_bodies(marker.args[0], soft):
            item.add_marker(pytest.mark.soft)  # before pytest's own -m deselection, which runs after this hook
    uses_sync = [item for item in items if "sync_implementation" in getattr(item, "fixturenames", ())]
    for item in uses_sync:
        item.add_marker(pytest.mark.sync)
    ordering.fail_fast(items, lambda item: "sync_implementation" in getattr(item, "fixturenames", ()))
    for item in uses_sync:  # under --dist loadgroup a scene's checks share its run on one worker (shared_run)
        marker = item.get_closest_marker("scene")
        if marker is not None:
            item.add_marker(pytest.mark.xdist_group(marker.args[0]))
    if not uses_sync:
        return
    from conformance.errors import SyncError
    from conformance.sync import load

    try:
        config.stash[_SYNC_KEY] = _limited(config, load(_sync_spec(config)))
    except SyncError as err:
        raise pytest.UsageError(str(err)) from None


def _has_soft_bodies(scene: str, known: dict) -> bool:
    """Whether ``scene`` is one of the registered scenes with soft bodies (``SceneSpec(deformable=True)``);
    ``known`` caches the answers of one collection."""
    if scene not in known:
        from conformance import scenes

        known[scene] = scene in scenes.names() and bool(scenes.get(scene).deformable)
    return known[scene]


def _limited(config: pytest.Config, implementation):
    """``implementation`` with the time limit per call in force (``--conformance-sync-timeout``)."""
    seconds = _option(config, "sync_timeout")
    return implementation if seconds is None else dataclasses.replace(implementation, time_limit=seconds)


@pytest.fixture(scope="session")
def sync_implementation(request: pytest.FixtureRequest):
    """The loaded sync implementation under test (see ``conformance.sync``)."""
    try:
        return request.config.stash[_SYNC_KEY]
    except KeyError:  # collected in an unusual way (e.g. a plugin added items late): load now
        from conformance.sync import load

        implementation = _limited(request.config, load(_sync_spec(request.config)))
        request.config.stash[_SYNC_KEY] = implementation
        return implementation


@pytest.fixture(scope="session")
def pictures(request: pytest.FixtureRequest):
    """Where goldens are read and failure pictures written, and the image tolerance in force."""
    from conformance.checks import image_options

    return image_options.from_config(request.config)


@pytest.fixture
def kit(request: pytest.FixtureRequest, sync_implementation):
    """The sync under test, the tolerances in force, and a recorder for this check's worst error."""
    from conformance.checks.pytest_helpers import Kit

    return Kit(sync_implementation, tolerance_from(request.config), request.node)


#: The figures a check noted (:mod:`conformance.figures`), for its record.
_FIGURES = pytest.StashKey[dict]()


def _is_the_kits(item: pytest.Item) -> bool:
    """Whether ``item`` is one of the kit's checks (a file of this package), not a test of the user's."""
    from pathlib import Path

    return Path(__file__).resolve().parent in Path(str(item.path)).resolve().parents


@pytest.hookimpl(wrapper=True)
def pytest_runtest_call(item: pytest.Item):
    from conformance import figures

    with figures.tally() as kept:
        item.stash[_FIGURES] = kept
        return (yield)


@pytest.hookimpl(wrapper=True, tryfirst=True)  # outermost: after Hypothesis' wrapper has added its patch
def pytest_runtest_makereport(item: pytest.Item, call):
    report = yield
    from conformance.checks import survey

    if _is_the_kits(item):
        # Hypothesis offers a patch "to add failing test cases to your code" for every failing draw, even
        # an expected failure's: here it would edit the kit's installed files, not the user's code.
        report.__dict__.pop("_hypothesis_failing_examples", None)
    from conformance.rendering.records import GOLDEN_VERDICTS

    _only_the_paragraph(call, report)
    survey.settle(item, report)  # survey mode: a check that noted failures fails now, naming every kind
    if report.when == "call":
        from conformance.checks import image_options
        from conformance.reports import misplaced

        misplaced.keep(item, report, image_options.from_config(item.config))
    if report.when == "call" and report.failed and _is_property(item):
        _say_how_shrunk(report)
    if report.when == "call" or report.outcome != "passed":
        marker = item.get_closest_marker("scene")
        message = ""
        if report.failed and report.longrepr is not None:
            message = str(getattr(report.longrepr, "reprcrash", None) and report.longrepr.reprcrash.message or report.longrepr)
        # On the report, not in this process: under pytest-xdist the report travels to the controller,
        # which is the one process that prints the verdicts and writes the JSON.
        report.user_properties.append((_RECORD_PROPERTY, {
            "nodeid": report.nodeid,
            "check": getattr(item, "originalname", item.name),
            "scene": marker.args[0] if marker is not None else None,
            "when": report.when,
            "outcome": "xfailed" if hasattr(report, "wasxfail") and report.skipped else report.outcome,
            "verdict": report.outcome,
            "worst": item.stash.get(survey.WORST, None),
            "worst_normals": item.stash.get(survey.WORST_NORMALS, None),
            "figures": item.stash.get(_FIGURES, {}),
            "kinds": survey.kinds_of(item, report, message),
            "message": message.strip().splitlines()[0][:4000] if message.strip() else "",
            # test_golden_render: each golden frame's sync and renderer verdicts (conformance.rendering.reftest).
            "golden_verdicts": [v for k, v in item.user_properties if k == GOLDEN_VERDICTS],
            "diagnosis": _after(message, "diagnosis: ", leading=True),
            "reproduce": _after(message, "reproduce: "),
        }))
    if _is_the_kits(item):
        from conformance.reports import junit

        junit.lead_with_the_diagnosis(report)  # after the record, which keeps the message as the check made it
    return report


def _after(message: str, label: str, *, leading: bool = False) -> str:
    """What follows ``label`` on the first line of ``message`` that has it (``leading``: that starts with it,
    indented or not), or ''."""
    for line in message.splitlines():
        text = line.strip()
        at = (0 if text.startswith(label) else -1) if leading else text.find(label)
        if at >= 0:
            return text[at + len(label):]
    return ""


def _only_the_paragraph(call, report: pytest.TestReport) -> None:
    """A renderer or display that cannot start fails its check with the kit's paragraph alone: it
    names the display, the driver and what to try, and the traceback through the backend adds nothing."""
    from conformance.errors import BackendError, DisplayUnavailable

    if report.failed and call.excinfo is not None and call.excinfo.errisinstance((BackendError, DisplayUnavailable)):
        report.longrepr = f"{call.excinfo.typename}: {call.excinfo.value}"


def _is_property(item: pytest.Item) -> bool:
    return bool(getattr(getattr(item, "obj", None), "is_hypothesis_test", False))


def _say_how_shrunk(report: pytest.TestReport) -> None:
    """Under a profile that reports counter-examples as found, a failing property says so and how to
    shrink it (the kit's ``reproduce:`` line replays it either way)."""
    if profiles.shrinks() or not hasattr(report.longrepr, "addsection"):
        return
    report.longrepr.addsection("conformance", (
        f"counter-example not shrunk: {profiles.describe()} reports the first one found, so that a wrong "
        "sync's verdict comes as quickly as a right one's. To shrink it, rerun this check with "
        "--hypothesis-profile shrink (or ci)."))


class _Records:
    """Collects the records that ride on reports, in the process that writes them out (pytest's own,
    or the pytest-xdist controller): registered per session, so nested sessions (pytester) keep theirs."""

    def __init__(self, config: pytest.Config):
        self.config = config

    def pytest_runtest_logreport(self, report: pytest.TestReport) -> None:
        if hasattr(self.config, "workerinput"):
            return
        if "conformance" in report.keywords:  # the kit's package name, among the keywords of each of its checks
            self.config.stash[_KIT_RAN_KEY] = True
        for name, record in report.user_properties:
            if name == _RECORD_PROPERTY:
                record = dict(record)
                verdict = record.pop("verdict")
                self.config.stash.setdefault(_RECORDS_KEY, []).append(record)
                if record["scene"] is not None:
                    self.config.stash[_VERDICT_KEY][record["scene"]][verdict].append(record["nodeid"])


def pytest_sessionfinish(session: pytest.Session, exitstatus) -> None:
    if hasattr(session.config, "workerinput"):  # under xdist, only the controller writes the page and the JSON
        return
    from conformance.checks import image_options

    image_options.from_config(session.config).write_report(_sync_spec(session.config))
    path = _option(session.config, "report")
    if not path:
        return
    import json

    from conformance.files import write_atomically

    records = session.config.stash.get(_RECORDS_KEY, [])
    from conformance import backends

    payload = {"sync": _sync_spec(session.config), "backend": backends.NAME, "fury": backends.fury_version(),
               "exitstatus": int(exitstatus), "records": records}
    write_atomically(path, json.dumps(payload, indent=1, default=float).encode("utf-8"))  # never half a report


class _Summary:
    """Writes the run's summary when the session ends, in the process that writes the report page (pytest's own,
    or the pytest-xdist controller): the second half of a wrapper, so after every plugin's ``pytest_sessionfinish``,
    when the page is written and the exit status final (the selection's check may make a green run's 5)."""

    @pytest.hookimpl(wrapper=True)
    def pytest_sessionfinish(self, session: pytest.Session):
        result = yield
        _write_summary(session)
        return result


def _write_summary(session: pytest.Session) -> None:
    """The run's Markdown summary, to the file ``--conformance-summary`` names and added to ``$GITHUB_STEP_SUMMARY``,
    in a session where a check of the kit reported (a suite of the user's own, in the same environment, gets none)."""
    import os

    from conformance.checks import image_options

    config = session.config
    pictures = image_options.from_config(config)
    options = _summary_targets(config)
    if not any(options) or not config.stash.get(_KIT_RAN_KEY, False):
        return
    from conformance import backends
    from conformance.errors import BackendError
    from conformance.reports import artefacts, summary

    try:
        backend = backends.describe()
    except BackendError:
        backend = "no FURY installed"
    selection = config.pluginmanager.get_plugin("conformance-selection")
    report = getattr(pictures, "report_path", None)
    github = [os.environ.get(name, "") for name in ("GITHUB_SERVER_URL", "GITHUB_REPOSITORY", "GITHUB_RUN_ID")]
    run = summary.Run(
        sync=_sync_spec(config), backend=backend, exitstatus=int(session.exitstatus),
        scenes=_scene_rows(config, _stopped(session, session.exitstatus)), records=config.stash.get(_RECORDS_KEY, []),
        pictures=artefacts.read_records(pictures.results), results=pictures.results, report=report,
        shard=config.getoption("conformance_shard"),
        artifacts=f"{github[0]}/{github[1]}/actions/runs/{github[2]}#artifacts" if all(github) else None,
        extra=[selection.message] if getattr(selection, "message", "") else [])
    path, step = options
    if path is not None:
        summary.write(run, path)
    if step is not None:
        summary.append(run, step)


def _summary_targets(config: pytest.Config) -> tuple:
    """(the ``--conformance-summary`` file, ``$GITHUB_STEP_SUMMARY``), each None when not given; checked when
    pytest was configured (:func:`conformance.validation.plugin_options`)."""
    from conformance import validation
    from conformance.errors import BadArgument

    try:
        return _option(config, "summary"), validation.step_summary()
    except BadArgument as err:
        raise pytest.UsageError(str(err)) from None


def pytest_deselected(items) -> None:
    if not items:
        return
    kept = items[0].config.stash.setdefault(_DESELECTED_KEY, {})
    why = items[0].config.stash.setdefault(_LEFT_OUT_KEY, {})
    for item in items:
        marker = item.get_closest_marker("scene")
        if marker is not None:
            kept[marker.args[0]] = kept.get(marker.args[0], 0) + 1
            reasons = why.setdefault(marker.args[0], {})
            reason = _why_deselected(item)
            reasons[reason] = reasons.get(reason, 0) + 1


def _why_deselected(item: pytest.Item) -> str:
    """What left ``item`` out: ``-k EXPR`` when the keyword expression does not match it (what was asked for
    names other scenes: the table leaves the scene out unsaid), else ``-m EXPR`` when the marker expression does
    not (``-m 'not soft'``, from the command line or the ini's ``addopts``), else ``--shard K/N``, else
    "deselected"."""
    option = item.config.option
    try:  # pytest's own matchers, as its -m and -k use them
        from _pytest.mark import KeywordMatcher, MarkMatcher
        from _pytest.mark.expression import Expression

        for flag, expression, matcher in (("-k", getattr(option, "keyword", ""), lambda: KeywordMatcher.from_item(item)),
                                          ("-m", getattr(option, "markexpr", ""), lambda: MarkMatcher.from_markers(item.iter_markers()))):
            if expression and not Expression.compile(expression).evaluate(matcher()):
                return f"{flag} {expression!r}"
    except Exception:  # pytest's internals moved, or its parser refused the expression: say less, never fail
        return "deselected"
    shard = item.config.getoption("conformance_shard", None)
    return f"--shard {shard}" if shard else "deselected"


def pytest_collection_finish(session: pytest.Session) -> None:
    if hasattr(session.config, "workeroutput"):  # for the pytest-xdist controller, which prints the verdicts
        # also when every check was left out (-m 'not soft' on the soft scenes alone): the table says why
        session.config.workeroutput["conformance_deselected"] = dict(session.config.stash.get(_DESELECTED_KEY, {}))
        session.config.workeroutput["conformance_left_out"] = dict(session.config.stash.get(_LEFT_OUT_KEY, {}))
    if not session.items:
        return
    counts: dict[str, int] = defaultdict(int)
    for item in session.items:
        marker = item.get_closest_marker("scene")
        if marker is not None:
            counts[marker.args[0]] += 1
    session.config.stash[_SELECTED_KEY] = dict(counts)
    if hasattr(session.config, "workeroutput"):
        session.config.workeroutput["conformance_selected"] = dict(counts)


@pytest.hookimpl(optionalhook=True)
def pytest_testnodedown(node, error) -> None:
    """pytest-xdist's controller: what each worker selected (every worker collects every check; a crashed
    one's replacement collects again), so that a scene not fully run is never called PASS."""
    counts = getattr(node, "workeroutput", {}).get("conformance_selected")
    if counts:
        kept = node.config.stash.setdefault(_SELECTED_KEY, {})
        for scene, count in counts.items():
            kept[scene] = max(kept.get(scene, 0), count)
    for scene, count in getattr(node, "workeroutput", {}).get("conformance_deselected", {}).items():
        left_out = node.config.stash.setdefault(_DESELECTED_KEY, {})
        left_out[scene] = max(left_out.get(scene, 0), count)
    for scene, reasons in getattr(node, "workeroutput", {}).get("conformance_left_out", {}).items():
        kept = node.config.stash.setdefault(_LEFT_OUT_KEY, {}).setdefault(scene, {})
        for reason, count in reasons.items():
            kept[reason] = max(kept.get(reason, 0), count)


def _scene_verdict(outcomes: dict, selected: int | None, stopped: bool) -> tuple[str, str]:
    """A scene's verdict word and its counts: FAIL if a check failed; PASS only when every check of it that
    the session selected ran and passed; INCOMPLETE when some did not run (the run was interrupted, or -x
    stopped it), NOT RUN when none did."""
    failed, passed, skipped = (len(set(outcomes.get(k, []))) for k in ("failed", "passed", "skipped"))
    ran = len({nodeid for nodeids in outcomes.values() for nodeid in nodeids})
    detail = f"{passed} passed" + (f", {failed} failed" if failed else "") + (f", {skipped} skipped" if skipped else "")
    if failed:
        missing = (selected - ran) if selected is not None and selected > ran else 0
        return "FAIL", detail + (f"; {missing} of its {selected} checks not run" if missing else "")
    if selected is not None and ran < selected:
        return ("INCOMPLETE" if ran else "NOT RUN"), (detail + "; " if ran else "") + f"{selected - ran} of its {selected} checks not run"
    if selected is None and stopped:
        return "INCOMPLETE", detail + "; the run stopped before every check ran"
    return ("PASS" if passed else "SKIP"), detail


def _stopped(session, exitstatus) -> bool:
    """Whether the run ended before every selected check ran (Ctrl-C, -x, --maxfail)."""
    return exitstatus == pytest.ExitCode.INTERRUPTED or bool(session is not None and (session.shouldstop or session.shouldfail))


def _scene_rows(config: pytest.Config, stopped: bool) -> list[tuple[str, str, str]]:
    """(verdict, scene, detail) of every scene the run reported or selected, in the order they reported; then
    each scene that a marker expression left out whole (``-m 'not soft'``: LEFT OUT, and why). A scene that
    only -k or --shard left out is not listed: those name the scenes a run is for."""
    verdicts = config.stash.get(_VERDICT_KEY, None) or {}
    selected = config.stash.get(_SELECTED_KEY, None)
    rows = []
    for scene in list(verdicts) + [scene for scene in (selected or {}) if scene not in verdicts]:
        verdict, detail = _scene_verdict(verdicts.get(scene, {}), selected.get(scene) if selected is not None else None, stopped)
        left_out = config.stash.get(_DESELECTED_KEY, {}).get(scene, 0)
        if left_out:  # a PASS of the checks that were asked for, not of the scene
            detail += f"; {left_out} of its checks not selected (-k, -m)"
        rows.append((verdict, scene, detail))
    for scene, reasons in config.stash.get(_LEFT_OUT_KEY, {}).items():
        if scene in verdicts or (selected or {}).get(scene) or not any(r.startswith("-m ") for r in reasons):
            continue
        count = sum(reasons.values())
        marks = {r: n for r, n in reasons.items() if r.startswith("-m ")}
        why = " and ".join(sorted(marks, key=lambda r: -marks[r]))
        rest = count - sum(marks.values())  # also not asked for by -k (or --shard): said, not blamed on -m
        said = f"{why} deselected its {count} checks" if not rest else \
            f"{why} deselected {count - rest} of its {count} checks, {' and '.join(r for r in reasons if r not in marks)} the other {rest}"
        rows.append(("LEFT OUT", scene, f"left out: {said}" + (" (a scene with soft bodies)" if _has_soft_bodies(scene, {}) else "")))
    return rows


def pytest_terminal_summary(terminalreporter, exitstatus, config: pytest.Config) -> None:
    from conformance.checks import image_options

    image_options.from_config(config).summarize(terminalreporter)
    tr = terminalreporter
    rows = _scene_rows(config, _stopped(getattr(tr, "_session", None), exitstatus))
    # Nothing reported: no table, unless -m left out every scene it would list (a run that checked nothing says why)
    if not config.stash.get(_VERDICT_KEY, None) and (
            not rows or config.option.collectonly or any(verdict != "LEFT OUT" for verdict, _, _ in rows)):
        return
    from conformance import backends

    tr.section(f"conformance verdict per scene (sync {_sync_spec(config)!r}, {backends.NAME} backend)")
    width = max(len(scene) for _, scene, _ in rows)
    words = max(len(verdict) for verdict, _, _ in rows)
    for verdict, scene, detail in rows:
        tr.write_line(f"{verdict:{max(words, 4)}}  {scene:<{width}}  {detail}", red=verdict == "FAIL",
                      yellow=verdict in ("INCOMPLETE", "NOT RUN"), green=verdict == "PASS")
