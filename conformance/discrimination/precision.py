"""Precision: how often the kit rejects a right sync or a right app, measured over many random draws.

The kill rate (:mod:`conformance.discrimination.verdicts`) shows every wrong sync rejected on the derandomized draws
every CI run makes; a user's CI runs the default profile, whose draws are random, and one false alarm
there turns a right program red (and the example database replays it on every later run). This runs
right syncs through the checks that draw at random (``-m draws``) under the ``precision`` profile: no
example database, nothing shrunk, ``factor`` times the default profile's examples per process, one
process per seed (``--hypothesis-seed``), so a process stands for ``factor`` default runs of each check
and a false alarm is replayed by its seed. Right apps get their own run and perturbed runs drawn from
each seed (:func:`conformance.apps.perturbed.search`).

What it reports, per check: how many default-profile runs of it were made, how many failed (each a
false alarm: the syncs and apps are right), and the worst use of each allowance over every draw
(:mod:`conformance.figures`), so a check drifting towards its bound shows before it fails. With no
false alarm in ``n`` runs, the rate is below 3/n at 95 % confidence (the rule of three): 3,000 runs of
a check see a rate of 1 in 1,000.
"""

from __future__ import annotations

import math
import shlex
import time
from dataclasses import dataclass, field

__all__ = ["SEED_VARIABLE", "AppDraw", "Journal", "SyncDraw", "app_draws", "draw_seed", "markdown", "rerun_command", "sync_draws"]

#: The environment variable that fixes :func:`draw_seed` (to replay a slice CI drew).
SEED_VARIABLE = "KIT_DRAW_SEED"


def draw_seed(directory=".") -> tuple[int, str]:
    """A seed for a slice of random draws that changes from commit to commit, and where it came from:
    ``$KIT_DRAW_SEED`` if set, else the first 8 hex digits of ``directory``'s git commit, else today's
    date. CI then tries new draws at every commit (a false alarm shows in some CI run, not in a user's),
    and the seed it prints replays them."""
    import datetime
    import os
    import subprocess

    from conformance import validation

    if os.environ.get(SEED_VARIABLE):
        return validation.whole_number(SEED_VARIABLE, os.environ[SEED_VARIABLE]), f"${SEED_VARIABLE}"
    try:
        commit = subprocess.run(["git", "rev-parse", "HEAD"], cwd=directory, capture_output=True, text=True,
                                timeout=30).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        commit = ""
    if len(commit) >= 8 and all(c in "0123456789abcdef" for c in commit[:8]):
        return int(commit[:8], 16), f"commit {commit[:12]}"
    today = datetime.date.today()
    return today.toordinal(), f"the date {today.isoformat()} (no git commit)"


@dataclass
class SyncDraw:
    """One process: a right sync through the drawing checks from one seed."""

    spec: str
    seed: int
    factor: int
    seconds: float
    exitstatus: int
    records: list[dict] = field(default_factory=list)
    stderr: str = ""
    select: str = ""   # pytest -k: only these of the drawing checks ran ("" = all of them)

    @property
    def false_alarms(self) -> list[dict]:
        return [r for r in self.records if r["outcome"] == "failed"]

    @property
    def broken(self) -> bool:
        """The process ended without its report or with an error that is no check's failure. Exit 5 with a
        report is not one when ``select`` picked only checks of pyBullet itself: the kit says "nothing of
        the sync was checked", which is what was asked."""
        return not self.records or self.exitstatus not in ((0, 1, 5) if self.select else (0, 1))


@dataclass
class AppDraw:
    """One right app: its own run and ``runs`` perturbed runs drawn from one seed."""

    app: str
    seed: int
    runs: int
    seconds: float
    failed: dict = field(default_factory=dict)   # check -> first line of its verdict
    worst: dict = field(default_factory=dict)    # check -> worst use of its allowance over the runs
    reproduce: str = ""
    error: str = ""


class Journal:
    """The draws made so far, one JSON line each, appended as each finishes (``precision --journal``): a
    run of hours can be stopped and started again, and goes on from where it was; the tables are made
    from every draw the journal holds."""

    _KEEP = ("nodeid", "check", "scene", "outcome", "message", "figures")

    def __init__(self, path):
        import json
        from pathlib import Path

        self.path = Path(path)
        self.made: dict[tuple, SyncDraw | AppDraw] = {}
        if self.path.exists():
            for number, line in enumerate(self.path.read_text(encoding="utf-8").splitlines(), 1):
                if not line.strip():
                    continue
                try:
                    entry = json.loads(line)
                    draw = SyncDraw(**entry["draw"]) if entry["kind"] == "sync" else AppDraw(**entry["draw"])
                except (ValueError, KeyError, TypeError):
                    continue  # a line cut short by a kill: that draw is made again
                self.made[self.key(draw)] = draw

    @staticmethod
    def key(draw) -> tuple:
        if isinstance(draw, SyncDraw):
            return ("sync", draw.spec, draw.seed, draw.factor, draw.select)
        return ("app", draw.app, draw.seed, draw.runs)

    def add(self, draw) -> None:
        import dataclasses
        import json
        import os

        entry = dataclasses.asdict(draw)
        if isinstance(draw, SyncDraw):
            entry["records"] = [{k: r.get(k) for k in self._KEEP} for r in draw.records]
            entry["stderr"] = draw.stderr[-1500:]
        line = json.dumps({"kind": "sync" if isinstance(draw, SyncDraw) else "app", "draw": entry}, default=float) + "\n"
        self.path.parent.mkdir(parents=True, exist_ok=True)
        if self.path.exists() and self.path.stat().st_size:
            with open(self.path, "rb") as seen:
                seen.seek(-1, os.SEEK_END)
                if seen.read(1) != b"\n":  # the last line was cut short by a kill: start a line of our own
                    line = "\n" + line
        with open(self.path, "a", encoding="utf-8") as out:  # one write a line: a kill loses at most the line
            out.write(line)
            out.flush()
            os.fsync(out.fileno())
        self.made[self.key(draw)] = draw


def _run_all(todo, make, journal, jobs, what):
    """``make(item)`` for every item not in ``journal`` yet, ``jobs`` at a time; the journal's draws for the rest."""
    from concurrent.futures import ThreadPoolExecutor, as_completed

    from conformance.progress import progress

    results = {}
    with ThreadPoolExecutor(max_workers=jobs or 1) as pool:
        futures = {}
        for key, item in todo:
            if journal is not None and key in journal.made:
                results[key] = journal.made[key]
            else:
                futures[pool.submit(make, item)] = key
        for future in progress(as_completed(futures), total=len(futures), what=what):
            results[futures[future]] = future.result()
            if journal is not None:
                journal.add(results[futures[future]])
    return [results[key] for key, _ in todo]


def pytest_args(seed: int, select: str = "") -> list[str]:
    """What each process adds to :func:`conformance.discrimination.verdicts.command`: the drawing checks (those ``-k select``
    picks, if given), the precision profile, the seed."""
    return ["-m", "draws", *(["-k", select] if select else []), "--hypothesis-profile", "precision",
            f"--hypothesis-seed={seed}"]


def rerun_command(spec: str, seed: int, factor: int, nodeid: str = "") -> str:
    """The command that replays one process's draws (and, with ``nodeid``, only that check)."""
    from conformance.checks.profiles import DRAW_FACTOR

    select = ["-k", nodeid.split("::", 1)[-1]] if nodeid else []
    from conformance.sync import printed

    return f"{DRAW_FACTOR}={factor} " + shlex.join([printed.python(), "-m", "pytest", "--pyargs", "conformance", "--sync", spec,
                                                    *pytest_args(seed), *select])


def sync_draws(specs, seeds, *, factor: int, select: str = "", jobs: int | None = None, timeout: float | None = None,
               journal: Journal | None = None) -> list[SyncDraw]:
    """Every right sync of ``specs`` through the drawing checks (those ``pytest -k select`` picks, if given)
    once per seed, ``jobs`` processes at a time (those the ``journal`` holds already are not made again)."""
    import os

    from conformance.discrimination import verdicts
    from conformance.checks.profiles import DRAW_FACTOR

    env = {**os.environ, DRAW_FACTOR: str(factor)}

    def one(item) -> SyncDraw:
        spec, seed = item
        start = time.monotonic()
        outcome = verdicts.check(spec, pytest_args=pytest_args(seed, select), env=env, timeout=timeout)
        return SyncDraw(spec, seed, factor, time.monotonic() - start, outcome.exitstatus, outcome.records, outcome.stderr,
                        select)

    todo = [(("sync", spec, seed, factor, select), (spec, seed)) for spec in specs for seed in seeds]
    return _run_all(todo, one, journal, jobs, "draws made")


def _per_spec(draws) -> str:
    counts: dict[str, int] = {}
    for d in draws:
        counts[d.spec] = counts.get(d.spec, 0) + 1
    return ", ".join(f"`{spec}` {n} seed{'s' if n != 1 else ''}" for spec, n in counts.items())


def app_draws(paths, seeds, *, runs: int, jobs: int | None = None, timeout: float | None = None,
              journal: Journal | None = None) -> list[AppDraw]:
    """Every right app of ``paths``: its own run, then ``runs`` perturbed runs drawn from each seed."""
    from conformance import apps
    from conformance.apps import perturbed

    def one(item) -> AppDraw:
        path, seed = item
        start = time.monotonic()
        draw = AppDraw(str(path), seed, runs, 0.0)
        try:
            result = apps.check_app(path, timeout=timeout)
            if result.passed and runs:
                found = perturbed.search(path, examples=runs, timeout=timeout, seed=seed)
                result = found or result
        except apps.AppFailed as err:
            draw.error = str(err)
            draw.reproduce = apps.reproduce_command(str(path), apps.DEFAULT_TICKS)
        except Exception as err:  # noqa: BLE001 - the kit failed on a right app: a rejection to count, not the end of the run
            # Raised, it ended the journal: the pool made every later draw and none was written (a FURY 0.12
            # measurement, 2026-11-28, wrote nothing for 45 minutes after one draw failed this way).
            draw.error = f"the kit itself failed: {type(err).__name__}: {err}"
            draw.reproduce = apps.reproduce_command(str(path), apps.DEFAULT_TICKS)
        else:
            for check, verdict in result.verdicts.items():
                if not verdict.passed:
                    draw.failed[check] = (verdict.lines or ["failed"])[0]
                if verdict.worst is not None:
                    draw.worst[check] = float(verdict.worst)
            draw.reproduce = result.reproduce() if draw.failed else ""
        draw.seconds = time.monotonic() - start
        return draw

    # seed by seed, every app in each: a long run stopped part-way has made draws of every app
    todo = [(("app", str(path), seed, runs), (path, seed)) for seed in seeds for path in paths]
    return _run_all(todo, one, journal, jobs, "app draws made")


def _scene_of(record: dict) -> str:
    return f"[{record['scene']}]" if record.get("scene") else ""


def _worst(figures: dict, kept: dict, where: str) -> None:
    for allowance, figure in figures.items():
        old = kept.get(allowance)
        if old is None or (not math.isnan(old["use"]) and not (old["use"] >= figure["use"])):  # NaN is the worst
            kept[allowance] = {**figure, "where": f"{figure.get('where', '')} ({where})".strip()}


def _use(value: float) -> str:
    return "NaN" if math.isnan(value) else ("∞" if math.isinf(value) else f"{value:.1%}")


def markdown(syncs: list[SyncDraw], app_runs: list[AppDraw], *, made_by: str, backend: str) -> str:
    """The precision tables: per check, runs, false alarms and the worst use of each allowance; per app,
    runs, false alarms and each check's worst use; then every false alarm with the command that replays it."""
    lines = [f"### Precision, {backend}", "", f"<!-- generated by `{made_by}`; do not edit -->", "", f"Made by `{made_by}`.", ""]
    alarms: list[str] = []
    if syncs:
        specs = sorted({d.spec for d in syncs})
        seconds = sum(d.seconds for d in syncs)
        runs: dict[str, int] = {}
        failed: dict[str, int] = {}
        worst: dict[str, dict] = {}
        for draw in syncs:
            for record in draw.records:
                if record["outcome"] not in ("passed", "failed"):
                    continue  # an xfailed check documents a deviation of pyBullet's, not a draw of ours
                # One row per check, its scenes together: each scene's runs are runs of the check.
                check = record["check"]
                runs[check] = runs.get(check, 0) + draw.factor
                worst.setdefault(check, {})
                _worst(record.get("figures") or {}, worst[check], f"{_scene_of(record)} {draw.spec}, seed {draw.seed}".strip())
                if record["outcome"] == "failed":
                    failed[check] = failed.get(check, 0) + 1
                    alarms.append(f"- `{check}{_scene_of(record)}`, sync `{draw.spec}`, seed {draw.seed}: {record['message'][:400]}\n  "
                                  f"replay: `{rerun_command(draw.spec, draw.seed, draw.factor, record['nodeid'])}`")
        broken = [d for d in syncs if d.broken]
        total = sum(failed.values())
        lines += [f"**Syncs**: {len(specs)} right, {len(syncs)} processes ({_per_spec(syncs)}; each "
                  f"{syncs[0].factor}x the default profile's examples"
                  + "".join(sorted({f"; only the checks `-k {d.select}` picks" for d in syncs if d.select})) + "), "
                  f"{seconds / 60:.1f} CPU-minutes of processes: **{total} false alarm{'s' if total != 1 else ''}** "
                  f"in {sum(runs.values())} default-profile runs of {len(runs)} checks.", ""]
        if broken:
            lines += [f"{len(broken)} processes ended without a report (not counted): "
                      + "; ".join(f"`{d.spec}` seed {d.seed}: {d.stderr.strip()[-200:]}" for d in broken[:5]), ""]
        lines += ["| check | runs | false alarms | worst use of each allowance (where) |", "|---|---|---|---|"]
        for check in sorted(runs):
            uses = "<br>".join(f"{name}: {_use(f['use'])} ({f['where']})" for name, f in
                               sorted(worst[check].items(), key=lambda kv: -kv[1]["use"] if not math.isnan(kv[1]["use"]) else -math.inf))
            lines.append(f"| `{check}` | {runs[check]} | {failed.get(check, 0)} | {uses or '–'} |")
        lines.append("")
    if app_runs:
        apps = sorted({d.app for d in app_runs})
        lines += [f"**Apps**: {len(apps)} right, {len(app_runs)} draws (own run + {app_runs[0].runs} perturbed runs each), "
                  f"{sum(d.seconds for d in app_runs) / 60:.1f} minutes: "
                  f"**{sum(bool(d.failed or d.error) for d in app_runs)} rejected**.", "",
                  "| app | draws | rejected | worst use of each check's allowance |", "|---|---|---|---|"]
        for app in apps:
            mine = [d for d in app_runs if d.app == app]
            worst_app: dict[str, float] = {}
            for d in mine:
                for check, value in d.worst.items():
                    if not (worst_app.get(check, -math.inf) >= value):
                        worst_app[check] = value
                if d.failed or d.error:
                    first = next(iter(d.failed.items()), ("runs", d.error))
                    alarms.append(f"- app `{app}`, seed {d.seed}: {first[0]}: {first[1][:400]}\n  replay: `{d.reproduce}`")
            uses = ", ".join(f"{check} {_use(v)}" for check, v in sorted(worst_app.items(), key=lambda kv: -kv[1]))
            lines.append(f"| `{app}` | {len(mine)} | {sum(bool(d.failed or d.error) for d in mine)} | {uses or '–'} |")
        lines.append("")
    lines += ["False alarms:", "", *(alarms or ["none."])]
    return "\n".join(lines)
