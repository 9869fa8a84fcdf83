"""Which checks a run executes (:mod:`conformance.session.selection`): shards partition the checks, a ``-k``
word that matches nothing stops the run, and a run asked to check a sync that ran no check of it
is not green. Each run here is pytest on the kit, collect-only where that is enough."""

from __future__ import annotations

import os
import re
import subprocess
import sys

import pytest
from hypothesis import given, settings, strategies as st

from conformance.session import selection


def _pytest(*args: str, env_sync: str | None = None) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if k != "CONFORMANCE_SYNC"}
    if env_sync is not None:
        env["CONFORMANCE_SYNC"] = env_sync
    return subprocess.run([sys.executable, "-m", "pytest", "--pyargs", "conformance", "-p", "no:cacheprovider", *args],
                          capture_output=True, text=True, env=env, timeout=600)


def _collected(*args: str) -> list[str]:
    proc = _pytest("--collect-only", "-q", *args)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    return [line for line in proc.stdout.splitlines() if "::" in line]


@pytest.mark.parametrize("n", [2, 3])
@pytest.mark.full("whole runs split into shards: tooling, not discrimination")
def test_shards_run_every_check_exactly_once(n):
    everything = _collected()
    shards = [_collected("--shard", f"{k}/{n}") for k in range(1, n + 1)]
    together = [nodeid for shard in shards for nodeid in shard]
    assert sorted(together) == sorted(everything), "the shards' union is not the whole run, or a check is in two shards"
    assert max(map(len, shards)) - min(map(len, shards)) <= 1, [len(s) for s in shards]


@pytest.mark.full("whole runs split into shards: tooling, not discrimination")
def test_shards_split_what_k_selected():
    chain = _collected("-k", "chain")
    halves = _collected("-k", "chain", "--shard", "1/2") + _collected("-k", "chain", "--shard", "2/2")
    assert sorted(halves) == sorted(chain) and all("chain" in nodeid for nodeid in halves)


@given(text=st.sampled_from(["0/3", "4/3", "3", "1/0", "a/b", "1/2/3", "-1/2", "", " / "]) | st.text(max_size=6))
@settings(max_examples=30, deadline=None)
def test_a_bad_shard_is_refused_naming_it(text):
    try:
        k, n = selection.parse_shard(text)
    except pytest.UsageError as err:
        assert f"--shard={text!r}" in str(err) and "K/N" in str(err)
    else:  # only well-formed shards get through
        assert re.fullmatch(r"\s*\d+\s*/\s*\d+\s*", text) and 1 <= k <= n


def test_a_bad_shard_stops_the_run():
    proc = _pytest("--collect-only", "-q", "--shard", "4/3")
    assert proc.returncode == pytest.ExitCode.USAGE_ERROR
    assert "--shard='4/3'" in proc.stderr


@pytest.mark.parametrize("workers", [[], ["-n", "2"]], ids=["serial", "xdist"])
def test_a_k_word_that_matches_nothing_stops_the_run(workers):
    proc = _pytest("-q", "-k", "chain or brick_wll", *workers)
    assert proc.returncode == pytest.ExitCode.USAGE_ERROR, proc.stdout[-2000:]
    said = proc.stdout + proc.stderr
    assert "'brick_wll' matches none of the" in said and "typo" in said
    assert " passed" not in said  # nothing ran


def test_k_words_that_match_are_left_alone():
    assert _collected("-k", "chain and not golden")


def test_a_run_asked_to_check_a_sync_that_ran_none_of_its_checks_is_not_green():
    only_physics = ["-q", "-k", "test_dynamic_bodies_collide_by_default"]
    proc = _pytest(*only_physics, env_sync="reference")
    assert proc.returncode == pytest.ExitCode.NO_TESTS_COLLECTED, proc.stdout[-2000:]
    assert "none of the checks it executed runs one" in proc.stdout
    # Without a sync named, checking only pybullet is a legitimate run.
    assert _pytest(*only_physics).returncode == pytest.ExitCode.OK
