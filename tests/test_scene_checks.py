"""Each scene check fails on a scene that breaks its promise (see ``bad_scenes``)."""

from __future__ import annotations

import pybullet
import pytest

import bad_scenes
from conformance import scenes
from conformance.checks import determinism
from conformance import test_scenes as checks

Failed = pytest.fail.Exception


@pytest.fixture
def register(monkeypatch):
    def _register(spec):
        monkeypatch.setitem(scenes.SCENES, spec.name, spec)
        return spec.name

    return _register


def test_determinism_check_fails_on_unseeded_randomness(register):
    name = register(bad_scenes.UNSEEDED)
    with pytest.raises(AssertionError, match="two runs with default parameters differ"):
        checks.test_is_deterministic_in_process(name)


def test_cross_process_check_fails_on_per_process_hash_salt(register, monkeypatch):
    monkeypatch.delenv("PYTHONHASHSEED", raising=False)
    name = register(bad_scenes.HASH_ORDERED)
    checks.test_is_deterministic_in_process(name)  # stable within one process...
    # ...but a fresh process salts str hashes differently; a few fresh processes make a miss unlikely
    # (3 names → 6 orders; the chance all 4 children agree with us by luck is (1/6)^4 < 0.1 %).
    with pytest.raises(AssertionError, match="in a fresh one"):
        for _ in range(4):
            checks.test_is_deterministic_across_processes(name, determinism.digests_in_subprocess([name]))


def test_disconnect_check_fails_on_a_leaked_client(register):
    name = register(bad_scenes.LEAKY)
    before = {c for c in range(256) if pybullet.isConnected(physicsClientId=c)}
    try:
        with pytest.raises(AssertionError, match="client left connected"):
            checks.test_disconnects_its_client(name)
    finally:
        for c in range(256):
            if c not in before and pybullet.isConnected(physicsClientId=c):
                pybullet.disconnect(physicsClientId=c)


def test_build_check_fails_on_a_binding_to_a_missing_link(register):
    name = register(bad_scenes.BAD_LINK)
    with pytest.raises(AssertionError, match="names link 3 of body 0, which has 0"):
        checks.test_builds_with_defaults(name)


def test_parameter_check_fails_when_parameters_break_the_physics(register):
    name = register(bad_scenes.EXPLODES)
    with pytest.raises(AssertionError, match="non-finite poses"):
        checks.test_builds_across_parameters(name)


def test_parameter_check_fails_without_a_strategy(register):
    name = register(bad_scenes.NO_STRATEGY)
    with pytest.raises(Failed, match="declares no parameter strategy"):
        checks.test_builds_across_parameters(name)


@pytest.mark.parametrize("when", ["first", "last"])
def test_geometry_check_fails_when_drawn_shape_is_not_the_collision_shape(register, when):
    name = register(bad_scenes.TOO_BIG)
    with pytest.raises(Failed, match=r"'ball' \(sphere\): vertex \d+ .* is 0.05 m off the sphere's surface"):
        checks.test_draws_its_collision_geometry(name, when)
