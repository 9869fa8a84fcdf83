"""The kit's own tests. ``pytester`` runs the kit end to end in this process, and after each run it
removes from ``sys.modules`` what the run imported. So every module of the kit is imported here, before
pytester snapshots ``sys.modules``: modules with native extensions cannot be imported twice in one process,
and a kit module dropped and imported again splits its classes in two (measured: after a pytester run
imported ``conformance.apps`` first, ``perturb.as_dict`` no longer knew the ``AfterStep`` that
``perturbed.opening`` made, and ``test_app_wrapped`` failed with a KeyError)."""

import importlib
import pkgutil

import PIL.Image  # noqa: F401
import pytest

import conformance


def _import_the_kit() -> None:
    """Every module of ``conformance`` (the other FURY's backend modules excepted: their FURY is not here)."""
    for module in pkgutil.walk_packages(conformance.__path__, "conformance."):
        if module.name != "conformance.__main__":
            try:
                importlib.import_module(module.name)
            except ModuleNotFoundError as exc:
                if exc.name not in ("vtkmodules", "vtk", "fury", "pygfx", "wgpu"):
                    raise


_import_the_kit()

pytest_plugins = ["pytester", "tiers"]  # tiers: the fast tier (CI) and --full

# `./kit test` runs these tests with the variable `./kit` sets for its commands; the commands the kit
# prints then name the kit's interpreter (conformance.sync.printed). The tests read those lines as a user who
# installed the kit where their `python` is; tests/test_printed_commands.py sets it back on purpose.
import os  # noqa: E402

os.environ.pop("CONFORMANCE_KIT_BACKEND", None)
# Run on GitHub Actions, every kit run these tests start would add its summary to the job's page (the plugin
# writes to $GITHUB_STEP_SUMMARY); the tests of the summary set it themselves.
os.environ.pop("GITHUB_STEP_SUMMARY", None)


def pytest_collection_modifyitems(items):
    """Tests that wait for a background run go last: until then this process runs everything else
    while the runs use the other cores (``background``)."""
    waits = [hasattr(getattr(item, "module", None), "background_runs") for item in items]
    items[:] = [item for item, w in zip(items, waits) if not w] + [item for item, w in zip(items, waits) if w]


@pytest.hookimpl(tryfirst=True)
def pytest_runtestloop(session):
    """Start the subprocess runs the selected tests will need, all at once (see ``background``); when the
    tests start, not when collection ends, so that a run refused after collection (a -k typo) starts none
    and does not wait minutes for them at its end."""
    if hasattr(session.config, "workerinput") or session.config.getoption("collectonly"):
        return
    import background

    runs = {}
    for module in {item.module for item in session.items if hasattr(item, "module")}:
        planner = getattr(module, "background_runs", None)
        if planner is not None:
            runs.update(planner([item for item in session.items if getattr(item, "module", None) is module]))
    if runs:  # the runs' apps, forked by the app server, start where it did: here, before any test changes directory
        from conformance.apps import launch

        launch.start_server()
        background.share_states()
    background.start_all(runs)


def pytest_sessionfinish(session):
    import background

    background.stop()


def pytest_report_header(config):
    """The seed of this run's random-draw slice (``tests/test_random_draws.py``), and how to replay it."""
    from pathlib import Path

    from conformance.discrimination import precision

    seed, source = precision.draw_seed(Path(__file__).resolve().parent.parent)
    return [f"random-draw slice: seed {seed} (from {source}; {precision.SEED_VARIABLE}={seed} replays it)"]
