"""App checks: your own programs, as they are, beside the kit's scenes.

List them in the ini file (``conformance_apps = apps/*.py``, globs relative to the rootdir, ``{backend}``
standing for ``vtk`` or ``pygfx``) or on the command line (``--conformance-app PATH``, repeatable). Each
app gets one check per verdict of :mod:`conformance.apps.judge` (``test_app[APP-attached]`` …), judged on
one run of the app (:func:`conformance.apps.check_app`, shared by its checks), and
``test_app_perturbed[APP]``: runs with the kit's teleports, kicks and joint resets between ticks, drawn
by Hypothesis (:mod:`conformance.apps.perturbed`). Each failure ends with the command that replays it; a
failing ``pictured`` check also names its pictures, written where the scene checks' silhouettes go.
"""

from __future__ import annotations

import pytest

from conformance import apps as app_mode
from conformance.apps import perturbed
from conformance.apps.verdict import lead_line

_RUNS: dict = {}


def pytest_generate_tests(metafunc):
    if "app" in metafunc.fixturenames:
        from conformance.plugin import app_paths

        paths = app_paths(metafunc.config)
        metafunc.parametrize("app", [pytest.param(p, id=p.name, marks=[pytest.mark.scene(f"app:{p.name}"),
                                                                        pytest.mark.xdist_group(f"app:{p}")])
                                     for p in paths] or [pytest.param(None, id="no-apps")])


def _own_run(config, app):
    from conformance.plugin import app_ticks, tolerance_from

    key = (str(app), app_ticks(config))
    if key not in _RUNS:
        try:
            _RUNS[key] = app_mode.check_app(app, ticks=key[1], tolerance=tolerance_from(config))
        except app_mode.AppFailed as err:
            _RUNS[key] = err
    return _RUNS[key]


def _kept(verdict, result, pictures, request) -> str:
    """The ``pictured`` check's pictures, written where the scene checks' go; a line naming them."""
    from conformance.apps import pictured

    paths = pictured.keep(verdict, pictures.results, result.reproduce(), request.node.nodeid, pictures.keep_passing)
    return f"\npictures (under {pictures.results}): {', '.join(paths)}" if paths and not verdict.passed else ""


@pytest.mark.parametrize("check", app_mode.CHECKS)
def test_app(app, check, request, pictures):
    """The app's own run passes ``check`` (:mod:`conformance.apps.judge` says what each guarantees)."""
    result = _own_run(request.config, app)
    if isinstance(result, app_mode.AppFailed):
        pytest.fail(f"{app}: {result}", pytrace=False)
    verdict = result.verdicts[check]
    kept = _kept(verdict, result, pictures, request) if check == "pictured" else ""
    if not verdict.passed:
        lead = lead_line(result.verdicts)
        pytest.fail(f"{check} [app {app}, {result.recording.ticks} ticks]\n{lead + chr(10) if lead else ''}"
                    f"{verdict.message()}{kept}\n"
                    f"reproduce: {result.reproduce()}", pytrace=False)


@pytest.mark.draws
def test_app_perturbed(app, request, pictures):
    """The app passes every check when the kit turns, kicks and resets its bodies between ticks: a sync
    right only for the motions the app happens to produce fails here."""
    from conformance.checks import profiles
    from conformance.plugin import tolerance_from

    own = _own_run(request.config, app)
    if isinstance(own, app_mode.AppFailed) or not own.passed:
        pytest.fail(f"{app}: its own run fails (see test_app[{app.name}-…]); not perturbed", pytrace=False)
    found = perturbed.search(app, examples=profiles.app_examples(), tolerance=tolerance_from(request.config))
    if found is not None:
        failing = {k: v for k, v in found.verdicts.items() if not v.passed}
        lines = "\n".join([lead_line(found.verdicts)] * bool(lead_line(found.verdicts))
                           + [f"{k}: {v.message()}" for k, v in failing.items()])
        kept = _kept(found.verdicts["pictured"], found, pictures, request) if "pictured" in failing else ""
        pytest.fail(f"perturbed run of {app} (events as drawn, not shrunk)\n{lines}{kept}\nreproduce: {found.reproduce()}",
                    pytrace=False)
