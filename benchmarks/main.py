"""One bench run: what to measure (:class:`Options`), measuring it, and everything measured (:class:`Results`)."""

from __future__ import annotations

import datetime
import gc
from dataclasses import dataclass, field
from typing import Callable

from conformance.progress import progress

from . import app_mode, machine, pictures, reads, suite, syncs, targets

__all__ = ["DEFAULT_PARTS", "PARTS", "Options", "Results", "run"]

#: What a run can measure (``--only``); ``apps`` (app mode's cost, a minute or two) and ``suite``
#: (minutes) only when asked.
PARTS = ("syncs", "reads", "pictures", "apps")
DEFAULT_PARTS = ("syncs", "reads", "pictures")


@dataclass(frozen=True)
class Options:
    sizes: tuple[int, ...] = (100, 1_000, 10_000)
    repeats: int = 15
    subject: str = "reference"  # the sync the targets judge
    parts: tuple[str, ...] = DEFAULT_PARTS
    suite: bool | str = False  # True or "all": every whole run; "checks": all but ./kit test
    suite_repeats: int = 1
    picture_scenes: tuple[str, ...] = pictures.SCENES
    frames: int | None = None  # frames per round of the sync figures (default: by size, syncs.frames_per_round)
    limits: targets.Limits = targets.Limits()

    def __post_init__(self):
        if not self.sizes or any(n < 1 for n in self.sizes):
            raise ValueError(f"sizes={self.sizes!r}, but should be one or more body counts, each at least 1")
        if self.repeats < 1 or self.suite_repeats < 1:
            raise ValueError(f"repeats={self.repeats!r}, suite_repeats={self.suite_repeats!r}, but should be at least 1")
        unknown = sorted(set(self.parts) - set(PARTS))
        if unknown:
            raise ValueError(f"parts={self.parts!r}: {', '.join(unknown)} unknown; the parts are {', '.join(PARTS)}")

    @property
    def reads_bodies(self) -> int:
        """Poses read per figure of the reads table: the second size (default 1,000), as the guide target."""
        sizes = sorted(set(self.sizes))
        return sizes[1] if len(sizes) > 1 else sizes[0]

    @property
    def specs(self) -> dict[str, list[str]]:
        """The syncs measured in each drawing style: the subject, ``reference``, the guide's recipes."""
        return {style: list(dict.fromkeys([self.subject, "reference", *syncs.GUIDE_RECIPES[style]]))
                for style in syncs.STYLES}


@dataclass
class Results:
    options: Options
    machine: dict
    started: str
    syncs: list = field(default_factory=list)
    verdicts: list = field(default_factory=list)
    reads: list = field(default_factory=list)
    pictures: list = field(default_factory=list)
    suite: list = field(default_factory=list)
    apps: list = field(default_factory=list)
    verdict_costs: list = field(default_factory=list)
    renderer: dict = field(default_factory=dict)


def _tasks(options: Options, results: Results) -> list[Callable[[], None]]:
    tasks = []
    if "syncs" in options.parts:
        for bodies in sorted(set(options.sizes)):
            for style in syncs.STYLES:
                tasks.append(lambda b=bodies, s=style: results.syncs.extend(
                    syncs.measure(b, s, options.specs[s], repeats=options.repeats, number=options.frames)))
    if "reads" in options.parts:
        tasks.append(lambda: results.reads.extend(reads.measure(options.reads_bodies, repeats=options.repeats)))
    if "pictures" in options.parts:
        from conformance import backends

        tasks.append(lambda: results.renderer.update(backends.renderer_info()))
        for name in options.picture_scenes:
            tasks.append(lambda n=name: results.pictures.extend(pictures.measure(n, repeats=options.repeats)))
    if "apps" in options.parts:
        from conformance import backends

        for name, script, environment in app_mode.apps(backends.NAME):
            tasks.append(lambda n=name, s=script, e=environment: results.apps.append(
                app_mode.measure(n, s, e, repeats=min(options.repeats, 3))))
        for name, right, wrong in app_mode.verdict_pairs(backends.NAME):
            tasks.append(lambda n=name, r=right, w=wrong: results.verdict_costs.append(
                app_mode.verdict_cost(n, r, w, repeats=min(options.repeats, 2))))
    if options.suite:
        runs = suite.commands(checks_only=options.suite == "checks")
        tasks.append(lambda: results.suite.extend(suite.measure(repeats=options.suite_repeats, baseline_repeats=3, runs=runs)))
    return tasks


def run(options: Options) -> Results:
    """Measure what ``options`` ask for (rendering needs a display: see the ``bench`` command)."""
    results = Results(options=options, machine=machine.machine(),
                      started=datetime.datetime.now().astimezone().isoformat(timespec="seconds"))
    tasks = _tasks(options, results)
    for task in progress(tasks, total=len(tasks), what="bench"):
        task()
        gc.collect()  # let the last task's actors and clients go before the next is timed
    results.verdicts = targets.evaluate(results.syncs, options.subject, options.limits) + targets.evaluate_suite(results.suite)
    return results
