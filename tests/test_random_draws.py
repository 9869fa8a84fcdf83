"""A slice of random draws in every CI run, new at every commit (issue 28, point 3).

The ``ci`` profile is derandomized, so every CI run and every kill-rate table tries the same draws;
a user's CI runs the default profile, whose draws are random, and a false alarm there turns a right
program red. So this file runs right programs through the checks that draw (``-m draws``) on draws
seeded by the commit (:func:`conformance.discrimination.precision.draw_seed`, printed in the session's header;
``KIT_DRAW_SEED=N`` replays a slice): ``reference``, one of ``tests/right_syncs`` (which one turns with
the seed), and one right example app with perturbed runs drawn from the seed. Over commits every right
sync and app meets new draws; ``python -m conformance precision`` measures the rate at scale
(docs/precision.md).
"""

from __future__ import annotations

import os
from pathlib import Path

import background
from conformance import backends
from conformance.discrimination import precision, verdicts

ROOT = Path(__file__).resolve().parent.parent
SEED, SOURCE = precision.draw_seed(ROOT)
RIGHT = verdicts.implementations("right_syncs")
APPS = sorted((ROOT / "examples" / backends.NAME).glob("*.py"))


def _env() -> dict[str, str]:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT / "tests"), *filter(None, env.get("PYTHONPATH", "").split(os.pathsep))])
    env.pop("CONFORMANCE_SYNC", None)
    return env


def _sync_run(spec: str, seed: int):
    return (f"random-draws:{spec}:{seed}",
            lambda: verdicts.check(spec, pytest_args=[*precision.pytest_args(seed), *background.OWN_SYNCS], env=_env()))


def _app_run(path: Path, seed: int):
    return f"random-draws:{path.name}:{seed}", lambda: precision.app_draws([str(path)], [seed], runs=2)[0]


PLAN = [("reference", SEED), (RIGHT[SEED % len(RIGHT)], SEED + 1)]
APP = APPS[SEED % len(APPS)]


def background_runs(items) -> dict:
    runs = {}
    for spec, seed in PLAN:
        key, call = _sync_run(spec, seed)
        runs[key] = (1, call)
    key, call = _app_run(APP, SEED)
    runs[key] = (1, call)
    return runs


def _replay(spec: str, seed: int) -> str:
    return f"PYTHONPATH=tests {precision.rerun_command(spec, seed, 1)}"


def test_right_syncs_pass_draws_seeded_by_the_commit():
    """``reference`` and a right sync of ``tests/right_syncs`` pass every drawing check on draws seeded
    by the commit (``--hypothesis-seed``; no example database, nothing shrunk)."""
    for spec, seed in PLAN:
        outcome = background.result(*_sync_run(spec, seed))
        failed = "\n".join(f"  {r['nodeid']}: {r['message'][:600]}" for r in outcome.failed[:3])
        assert outcome.exitstatus == 0 and outcome.records, (
            f"the right sync {spec} was rejected on the random draws of seed {seed} ({SOURCE}): a false alarm the "
            f"kit must not raise. Replay: `{_replay(spec, seed)}`\n{failed}\n{outcome.stderr[-800:]}")
        assert any(r["check"] == "test_sync_order_follows_any_order_of_calls" for r in outcome.records)


def test_a_right_example_app_passes_perturbed_runs_seeded_by_the_commit():
    """A right example app (which one turns with the seed) passes its own run and two perturbed runs drawn from the seed."""
    draw = background.result(*_app_run(APP, SEED))
    assert not draw.failed and not draw.error, (
        f"the right example app {APP.relative_to(ROOT)} was rejected on perturbed runs drawn from seed {SEED} "
        f"({SOURCE}): {draw.failed or draw.error}. Replay: `{draw.reproduce}`")
