"""A pytest run forked from the app server (:mod:`conformance.discrimination.forked`) is the run a new
process gives: the same exit status and records, the sync found through ``PYTHONPATH``, the kit's asserts
rewritten (no warning that they could not be), and a run past its time limit stopped."""

from __future__ import annotations

import os
import subprocess
import textwrap

import pytest

from conformance.discrimination import forked, verdicts

#: a sync that draws nothing: fails the first vertex check of free_fall
NOTHING = textwrap.dedent("""
    class DrawsNothing:
        def __init__(self, world):
            pass

        def __call__(self):
            pass
""")


@pytest.fixture
def env(tmp_path):
    (tmp_path / "draws_nothing.py").write_text(NOTHING, encoding="utf-8")
    environ = dict(os.environ)
    environ["PYTHONPATH"] = os.pathsep.join([str(tmp_path), *filter(None, environ.get("PYTHONPATH", "").split(os.pathsep))])
    return environ


def test_a_forked_run_is_the_run_a_new_process_gives(env):
    args = dict(stop_at_first=True, env=env, pytest_args=["--conformance-isolation", "none", "-k", "free_fall and poses_every_frame"])
    new, fork = (verdicts.check("draws_nothing:DrawsNothing", fork=f, **args) for f in (False, True))
    assert fork.exitstatus == new.exitstatus == pytest.ExitCode.TESTS_FAILED, (fork.stderr, new.stderr)
    assert [(r["check"], r["scene"], r["message"]) for r in fork.failed] == \
        [(r["check"], r["scene"], r["message"]) for r in new.failed]


def test_a_forked_run_rewrites_the_kits_asserts_as_a_new_process_does(env):
    done = forked.run(["--pyargs", "conformance", "-q", "-p", "no:cacheprovider", "-k", "test_builds_with_defaults and free_fall"],
                      env=env)
    if done is None:
        pytest.skip("no forkserver on this platform: the kit starts a new process instead")
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    assert "PytestAssertRewriteWarning" not in done.stdout + done.stderr, done.stdout[-2000:]


def test_a_forked_run_past_its_time_limit_is_stopped(env):
    with pytest.raises(subprocess.TimeoutExpired):
        forked.run(["--pyargs", "conformance", "-q", "-p", "no:cacheprovider", "--sync", "draws_nothing:DrawsNothing",
                    "-k", "tumbling"], env=env, timeout=0.5)
