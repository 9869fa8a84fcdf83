"""A sync plug-in that cannot be used gets one clear paragraph naming it and the problem, and the run fails.

Each case runs the kit end to end with ``pytester`` on the small ``free_fall`` scene.
"""

from __future__ import annotations

import textwrap

import pytest

from conformance import sync
from conformance.errors import SyncLoadError, SyncProtocolError

# In pytest's own process: these syncs live in pytester's directory, which pytester puts on this process's
# sys.path only, and these tests read the paragraphs, not where they ran (test_crashes.py runs in workers).
RUN = ["--pyargs", "conformance", "-k", "test_vertices_match_poses_every_frame and free_fall", "-p", "no:cacheprovider",
       "--conformance-isolation", "none"]


def _write(pytester, name: str, source: str) -> None:
    pytester.makepyfile(**{name: textwrap.dedent(source)})
    pytester.syspathinsert()


def _assert_clean_usage_error(result, *needles: str) -> None:
    assert result.ret == pytest.ExitCode.USAGE_ERROR
    err = result.stderr.str()
    for needle in needles:
        assert needle in err, f"{needle!r} not in:\n{err}"
    assert "Traceback" not in err and "Traceback" not in result.stdout.str()


@pytest.mark.parametrize(
    "spec, needles",
    [
        ("no_colon_here", ["'no_colon_here' is neither a short name", "module:attribute"]),
        ("no_such_module_xyz:Sync", ["importing module 'no_such_module_xyz' failed", "ModuleNotFoundError", "PYTHONPATH"]),
        (":Sync", ["neither a short name"]),
        # Issue 30, point 10: a path, as --scenes takes, said only "No module named 'mysim/sync'".
        ("mysim/sync.py:MySync", ["not a file's path: 'mysim.sync:MySync'", "the directory that holds 'mysim'"]),
        # An absolute path has no directory to run from that the dotted name could start at.
        ("/tmp/mysim/sync.py:MySync", ["'sync:MySync' with '/tmp/mysim' on PYTHONPATH"]),
    ],
)
def test_unloadable_spec_is_a_usage_error(pytester, spec, needles):
    _assert_clean_usage_error(pytester.runpytest(*RUN, "--sync", spec), *needles)


def test_module_that_raises_on_import(pytester):
    _write(pytester, "broken_sync_a", """
        raise ImportError("numpy.int is gone")
    """)
    result = pytester.runpytest(*RUN, "--sync", "broken_sync_a:Sync")
    _assert_clean_usage_error(result, "'broken_sync_a:Sync'", "ImportError: numpy.int is gone", "broken_sync_a.py:")


def test_missing_attribute_lists_what_exists(pytester):
    _write(pytester, "sync_b", """
        class Sink:
            def __init__(self, world): pass
            def __call__(self): pass
    """)
    result = pytester.runpytest(*RUN, "--sync", "sync_b:Sync")
    _assert_clean_usage_error(result, "has no attribute 'Sync'", "it defines Sink")


def test_attribute_not_callable(pytester):
    _write(pytester, "sync_c", "Sync = 42\n")
    result = pytester.runpytest(*RUN, "--sync", "sync_c:Sync")
    _assert_clean_usage_error(result, "'sync_c:Sync' is 42 (type int)", "should be a callable")


def test_factory_with_wrong_arity(pytester):
    _write(pytester, "sync_d", """
        def make(world, actors):
            return lambda: None
    """)
    result = pytester.runpytest(*RUN, "--sync", "sync_d:make")
    _assert_clean_usage_error(result, "has signature (world, actors)", "with one argument, the World")


def test_environment_variable_selects_the_sync(pytester, monkeypatch):
    monkeypatch.setenv(sync.ENV_VAR, "sync_from_env_e:Missing")
    _write(pytester, "sync_from_env_e", "X = 1\n")
    result = pytester.runpytest(*RUN)
    _assert_clean_usage_error(result, "'sync_from_env_e:Missing'")


def _assert_one_paragraph_failure(result, *needles: str) -> None:
    result.assert_outcomes(failed=1)
    out = result.stdout.str()
    for needle in needles:
        assert needle in out, f"{needle!r} not in:\n{out}"
    # pytrace=False: the report is the message, not a traceback through the kit's frames.
    assert "conformance/sync/runner.py" not in out and "def sync_run" not in out


def test_factory_that_raises_fails_the_check(pytester):
    _write(pytester, "sync_f", """
        class Sync:
            def __init__(self, world):
                raise KeyError("vertices")
            def __call__(self):
                pass
    """)
    result = pytester.runpytest(*RUN, "--sync", "sync_f:Sync")
    _assert_one_paragraph_failure(result, "'sync_f:Sync' raised while being set up for scene 'free_fall'",
                                  "KeyError: 'vertices'", "sync_f.py:")


def test_factory_returning_non_callable(pytester):
    _write(pytester, "sync_g", """
        def make(world):
            return [world]
    """)
    result = pytester.runpytest(*RUN, "--sync", "sync_g:make")
    _assert_one_paragraph_failure(result, "returned [", "should return a callable taking no arguments")


def test_step_that_raises_names_the_step(pytester):
    _write(pytester, "sync_h", """
        from conformance.implementations.reference import ReferenceSync

        class Sync(ReferenceSync):
            calls = 0
            def __call__(self):
                self.calls += 1
                if self.calls == 4:
                    raise ZeroDivisionError("bad frame")
                super().__call__()
    """)
    result = pytester.runpytest(*RUN, "--sync", "sync_h:Sync")
    _assert_one_paragraph_failure(result, "raised on scene 'free_fall' at step 3", "ZeroDivisionError: bad frame",
                                  "sync_h.py:")


def test_a_sync_on_the_default_client_fails_and_is_told_to_use_world_p(pytester):
    """The checks' scenes are never on pyBullet's default client 0 (a decoy holds it): a sync whose
    pybullet calls leave out the scene's client (the mutant ``a4f27042dd`` of the reference's fast path,
    docs/mutants-vtk.md) read an empty world and fail, told what to do, where on client 0 they drew the
    right poses by luck."""
    _write(pytester, "sync_client", """
        import pybullet
        from conformance.implementations.reference import ReferenceSync

        class Sync(ReferenceSync):
            def __call__(self):
                for t in self.targets:
                    pybullet.getBasePositionAndOrientation(t.body)  # no physicsClientId: client 0
                super().__call__()
    """)
    result = pytester.runpytest(*RUN, "--sync", "sync_client:Sync")
    _assert_one_paragraph_failure(result, "raised", "GetBasePositionAndOrientation failed",
                                  "client 0, the default of every pybullet call made without physicsClientId",
                                  "p = world.p")


def test_sync_writing_nan_fails_with_non_finite_message(pytester):
    _write(pytester, "sync_i", """
        import numpy as np
        import actor_data

        class Sync:
            def __init__(self, world):
                self.world = world
            def __call__(self):
                for t in self.world.targets:
                    actor_data.vertices(t.actor)[t.start:t.stop] = np.nan
                    actor_data.announce(t.actor)
    """)
    result = pytester.runpytest(*RUN, "--sync", "sync_i:Sync")
    _assert_one_paragraph_failure(result, "is drawn at non-finite coordinates", "[free_fall(", "reproduce: python -m conformance check free_fall --sync sync_i:Sync")


def test_load_errors_are_typed():
    with pytest.raises(SyncLoadError):
        sync.load("")
    with pytest.raises(SyncProtocolError):
        sync.load("math:pi")
    assert sync.load("reference").target == sync.SHORT_NAMES["reference"]
