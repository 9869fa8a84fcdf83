"""The bench's machinery, at tiny sizes: tables and JSON are made, the floor is measured, and every
target can miss. No assertion here is on how fast the kit's code is: only on the harness and on syncs
made slow (or wrong) on purpose."""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import pybullet
import pytest

from conformance import backends, cli
from conformance.commands import bench as bench_command

bench_command.benchmarks()  # the checkout's benchmarks/ on sys.path
from benchmarks import app_mode, floor, grid, pictures, report, suite, syncs, targets, timing  # noqa: E402
from benchmarks.main import Options, Results  # noqa: E402
from conformance.implementations.reference import ReferenceSync  # noqa: E402


class SlowSync(ReferenceSync):
    """Right, but reads every pose five more times a frame and sleeps a millisecond: far off the floor."""

    def __call__(self):
        for _ in range(5):
            for t in self.targets:
                pybullet.getBasePositionAndOrientation(t.body, physicsClientId=self.client)
        time.sleep(1e-3)
        super().__call__()


class QuadraticSync(ReferenceSync):
    """Right, but its cost grows with the square of the bodies: n² sums of 1,000 integers a frame (tens
    of µs each here). Work, not a sleep: a loaded machine slows both sizes alike, where a sleep's wake-up
    delay (milliseconds when the other backend's suite runs beside this one) swamped the 0.9 ms of the
    small size and made the quadratic sync look linear."""

    def __call__(self):
        for _ in range(len(self.targets) ** 2):
            sum(range(1000))
        super().__call__()


def idle_sync(world):
    """Fast because it does nothing: every body is left where it was built."""
    return lambda: None


HERE = __name__  # how this module was imported: the specs below name its syncs through it


# -- the timing harness ---------------------------------------------------------------------------

class FakeClock:
    def __init__(self):
        self.now = 0.0

    def __call__(self):
        return self.now


def test_race_keeps_each_candidates_best_round_and_does_not_time_before(monkeypatch):
    clock = FakeClock()
    monkeypatch.setattr(timing.time, "perf_counter", clock)
    costs = {"a": iter([5.0, 1.0, 3.0]), "b": iter([2.0, 2.0, 2.0])}
    order = []

    def call(name):
        def fn():
            order.append(name)
            clock.now += next(costs[name])
        return fn

    def before():
        clock.now += 100.0  # untimed

    best = timing.race([timing.Candidate("a", call("a"), before), timing.Candidate("b", call("b"))], repeats=3, number=1)
    assert best == {"a": 1.0, "b": 2.0}
    assert order == ["a", "b", "b", "a", "a", "b"]  # the order turns every round
    with pytest.raises(ValueError, match="at least 1"):
        timing.race([], repeats=0, number=1)


# -- the floor -------------------------------------------------------------------------------------

@pytest.mark.parametrize("shared", [False, True])
def test_floor_reads_every_pose_once_and_touches_every_actor(monkeypatch, shared):
    with grid.grid(5, shared=shared) as scene:
        drawing = backends.build(scene)
        sync = floor.Floor(drawing.world)
        reads = []
        real = pybullet.getBasePositionAndOrientation
        monkeypatch.setattr(pybullet, "getBasePositionAndOrientation",
                            lambda body, physicsClientId: reads.append(body) or real(body, physicsClientId=physicsClientId))
        before = {name: backends.content_state(a)[0] for name, a in drawing.actors.items()}
        poses_before = {name: _pose_stamp(a) for name, a in drawing.actors.items()}
        sync()
        assert sorted(reads) == sorted(t.body for t in drawing.targets)
        for name, actor in drawing.actors.items():
            if shared:
                assert backends.content_state(actor)[0] > before[name]  # Modified()/update_full() after the write
            else:
                assert _pose_stamp(actor) != poses_before[name]  # the one call per whole actor


def _pose_stamp(actor):
    """What a sync's pose write on a whole actor changes: on FURY 0.12 its user matrix (None until a
    sync gives it one); on FURY 2 when its transform last changed (``actor.local.last_modified``, ns)."""
    return actor.GetUserMatrix() if backends.NAME == "vtk" else actor.local.last_modified


# -- sync figures and targets ----------------------------------------------------------------------

@pytest.fixture(scope="module")
def figures():
    """The floor, reference, the guide recipes and three bad syncs at 3 and 12 bodies, both styles."""
    specs = ["reference", f"{HERE}:SlowSync", f"{HERE}:QuadraticSync", f"{HERE}:idle_sync"]
    out = []
    for bodies in (3, 12):
        for style in syncs.STYLES:
            out += syncs.measure(bodies, style, specs + list(syncs.GUIDE_RECIPES[style]), repeats=2, number=2)
    return out


def test_every_sync_figure_is_a_ratio_to_the_floor_of_its_size_and_style(figures):
    floors = {(f.style, f.bodies): f for f in figures if f.name == syncs.FLOOR}
    assert set(floors) == {(s, n) for s in syncs.STYLES for n in (3, 12)}
    assert all(f.seconds > 0 for f in floors.values())
    for f in figures:
        assert f.floor == floors[f.style, f.bodies].seconds
        assert f.ratio == pytest.approx(f.seconds / f.floor)
    steps = [f for f in figures if f.name == syncs.STEP]
    assert len(steps) == 4 and all(f.wrong is None for f in steps)


def test_the_vertex_check_tells_right_syncs_from_wrong_ones(figures):
    wrong = {(f.name, f.style, f.bodies): f.wrong for f in figures if f.wrong is not None}
    assert all(wrong["reference", s, n] == 0 for s in syncs.STYLES for n in (3, 12))
    assert all(wrong[f"{HERE}:idle_sync", s, n] == n for s in syncs.STYLES for n in (3, 12))
    if backends.NAME == "vtk":
        assert wrong["guide-actor", "whole", 12] == 12  # SetOrientation's Euler angles turn the wrong way
    else:
        assert wrong["guide-actor", "whole", 12] == 0  # FURY 2's local.rotation takes pybullet's quaternion as it is


def _verdicts(figures, subject):
    return {v.target: v for v in targets.evaluate(figures, subject)}


def test_a_slow_sync_misses_the_floor_and_guide_targets(figures):
    verdicts = _verdicts(figures, f"{HERE}:SlowSync")
    near = [v for t, v in verdicts.items() if "the floor" in t]
    faster = [v for t, v in verdicts.items() if "faster than" in t]
    assert len(near) == 2 and not any(v.passed for v in near)  # 12 bodies, both styles
    assert len(faster) == 2 and not any(v.passed for v in faster)
    assert all(v.passed for t, v in verdicts.items() if "draws every body right" in t)


def test_a_quadratic_sync_misses_the_linearity_target(figures):
    linear = [v for t, v in _verdicts(figures, f"{HERE}:QuadraticSync").items() if "linear" in t]
    assert len(linear) == 2 and not any(v.passed for v in linear)
    assert all("the floor's:" in v.note for v in linear)


def test_a_sync_that_skips_the_work_misses_the_right_drawing_target(figures):
    right = [v for t, v in _verdicts(figures, f"{HERE}:idle_sync").items() if "draws every body right" in t]
    assert len(right) == 2 and not any(v.passed for v in right)
    assert all("12 of 12 wrong" in v.measured for v in right)


def _figure(style, bodies, name, seconds, floor_seconds):
    return syncs.SyncFigure(style, bodies, name, seconds, floor_seconds, wrong=None if name == syncs.FLOOR else 0,
                            worst_error=None if name == syncs.FLOOR else 0.0)


def test_targets_pass_and_miss_on_the_numbers_and_say_when_the_floor_is_the_limit():
    figures = []
    for style in syncs.STYLES:
        guide = syncs.GUIDE_RECIPES[style][0]
        for bodies, floor_s, mine, theirs in ((100, 1e-4, 2e-4, 5e-4), (1000, 1e-3, 1.2e-3, 3.7e-3),
                                              (10000, 1e-2, 1.6e-2, 4e-2)):
            figures += [_figure(style, bodies, syncs.FLOOR, floor_s, floor_s),
                        _figure(style, bodies, "reference", mine, floor_s),
                        _figure(style, bodies, guide, theirs, floor_s)]
    verdicts = _verdicts(figures, "reference")
    whole = {t: v for t, v in verdicts.items() if "whole actors" in t}
    assert [v.passed for t, v in whole.items() if "the floor, " in t] == [True, False]  # 1.2× at 1,000, 1.6× at 10,000
    faster = next(v for t, v in whole.items() if "faster than `guide-actor`, whole actors, 1,000 bodies" in t)
    assert not faster.passed and faster.measured == "3.1×" and "out of reach" in faster.note and "3.7×" in faster.note
    linear = next(v for t, v in whole.items() if "linear" in t)
    assert linear.passed and linear.measured.startswith("1.33×")


# -- the command: tables, JSON, README ---------------------------------------------------------------

def test_bench_prints_tables_writes_json_and_fills_the_readme_block(tmp_path, capsys):
    readme = tmp_path / "README.md"
    block = bench_command._block()  # "bench" on FURY 0.12, "bench-pygfx" on FURY 2
    readme.write_text(f"# x\n\n<!-- conformance:{block} -->\nold\n<!-- /conformance:{block} -->\nafter\n", encoding="utf-8")
    out = tmp_path / "bench.json"
    status = cli.main(["bench", "--sizes", "3", "6", "--repeats", "1", "--only", "syncs", "reads",
                       "--json", str(out), "--readme", str(readme)])
    assert status == 0
    text = capsys.readouterr().out
    for expected in (_machine()["cpu"], "cores (", "pybullet 3.2", backends.describe(), "Python 3.",
                     "| one shared actor | **floor** |", "| whole actors | `reference` |", "`guide-actor`",
                     "`guide-vertex`", "`stepSimulation()`", "**Targets**", "**Reading poses**", "`getLinkStates("):
        assert expected in text, expected
    assert floor.DEFINITION in text  # the floor of the backend in force, and its own whole-actor writes read
    assert ("`vtkMatrix4x4.DeepCopy(" if backends.NAME == "vtk" else "`actor.local.matrix = M`") in text
    assert "**pass**" in text or "**miss**" in text
    data = json.loads(out.read_text(encoding="utf-8"))
    assert data["machine"]["pybullet"].startswith("3.2") and data["options"]["sizes"] == [3, 6]
    assert data["machine"]["backend"] == backends.NAME and data["machine"]["fury"].startswith(("0.12", "2."))
    assert {f["name"] for f in data["syncs"]} >= {"floor", "reference", "guide-actor", "guide-vertex", "stepSimulation()"}
    assert all(f["ratio"] == pytest.approx(f["seconds"] / f["floor"]) for f in data["syncs"])
    assert data["targets"] and all(isinstance(t["passed"], bool) for t in data["targets"])
    assert data["reads"][0]["ratio"] == pytest.approx(1.0)
    block = readme.read_text(encoding="utf-8")
    assert "old" not in block and "**Targets**" in block and block.endswith(f"<!-- /conformance:{bench_command._block()} -->\nafter\n")


def test_bench_refuses_bad_options_before_measuring(tmp_path, capsys):
    with pytest.raises(SystemExit):
        cli.main(["bench", "--sizes", "0"])
    assert "--sizes=0 (int), but should be a whole number from 1" in capsys.readouterr().err
    readme = tmp_path / "README.md"
    readme.write_text("no markers\n", encoding="utf-8")
    started = time.perf_counter()
    assert cli.main(["bench", "--readme", str(readme)]) == 2
    assert f"needs one line '<!-- conformance:{bench_command._block()} -->'" in capsys.readouterr().err
    assert time.perf_counter() - started < 5  # refused at once, not after the default run's minute
    with pytest.raises(ValueError, match="bogus"):
        Options(parts=("bogus",))


# -- pictures and whole runs ------------------------------------------------------------------------

def test_picture_figures_are_ratios_to_a_frame_of_the_scene():
    figures = pictures.measure("free_fall", repeats=1, number=1)
    by = {f.name: f for f in figures}
    assert by[pictures.FRAME].ratio == 1.0
    assert {"render + read-back", "pyBullet-renderer (silhouette) check"} <= set(by)
    assert all(f.size == (450, 384) and f.seconds > 0 for f in figures)


def test_whole_runs_are_timed_with_their_exit_status_and_tabled():
    runs = [("ok", [sys.executable, "-c", "print('= 2 failed, 7 passed, 1 skipped in 3.2s =')"]),
            ("fails", [sys.executable, "-c", "import sys; print('boom'); sys.exit(3)"])]
    figures = suite.measure(repeats=1, baseline_repeats=1, runs=runs, baseline=lambda: time.sleep(0.01))
    by = {f.name: f for f in figures}
    assert by[suite.BASELINE].ratio == 1.0 and by["ok"].returncode == 0 and by["ok"].seconds > 0
    assert by["fails"].returncode == 3 and "boom" in by["fails"].tail
    assert (by["ok"].failed, by["ok"].passed) == (2, 7) and by["fails"].failed is None, "counts from pytest's last line"
    text = report.markdown(Results(options=Options(parts=()), machine=_machine(), started="now", suite=figures))
    assert "**Whole runs**" in text and "| fails |" in text and "| 3 |" in text and "| 2 of 9 |" in text
    assert [name for name, _ in suite.commands()] == ["`pytest --collect-only conformance`", "`pytest conformance`",
                                                      "`pytest conformance -n 2`", suite.WRONG, suite.ISOLATED,
                                                      suite.IN_PROCESS, "`./kit test`"]
    assert [name for name, _ in suite.commands(checks_only=True)][-1] == suite.IN_PROCESS


def test_whole_runs_pass_their_time_limits_only_in_time_and_with_exit_0():
    base = dict(command="…", baseline=1.0)
    figures = [suite.SuiteFigure("`pytest conformance`", seconds=80.0, **base),
               suite.SuiteFigure("`pytest conformance -n 2`", seconds=61.0, **base),
               suite.SuiteFigure("`./kit test`", seconds=100.0, returncode=1, **base),
               suite.SuiteFigure("`pytest --collect-only conformance`", seconds=1.0, **base)]
    verdicts = {v.target.split(" within")[0]: v for v in targets.evaluate_suite(figures)}
    assert verdicts["`pytest conformance`"].passed
    assert not verdicts["`pytest conformance -n 2`"].passed  # over 60 s
    assert not verdicts["`./kit test`"].passed and "exit 1" in verdicts["`./kit test`"].measured
    assert len(verdicts) == 3  # collection has no limit


def test_a_wrong_syncs_full_run_is_judged_against_the_right_ones():
    def verdict(right, wrong, wrong_exit=1):
        figures = [suite.SuiteFigure(suite.RIGHT, command="…", baseline=1.0, seconds=right, failed=0, passed=295),
                   suite.SuiteFigure(suite.WRONG, command="…", baseline=1.0, seconds=wrong, returncode=wrong_exit,
                                     failed=97, passed=198)]
        return [v for v in targets.evaluate_suite(figures) if "wrong sync" in v.target][0]

    assert verdict(100.0, 140.0).passed and "1.40× (140 s against 100 s, 97 of 295 checks failed, exit 1)" in verdict(100.0, 140.0).measured
    assert not verdict(100.0, 160.0).passed, "over 1.5×"
    assert not verdict(100.0, 90.0, wrong_exit=0).passed, "a wrong sync that passes is no verdict"


def test_crash_isolation_is_judged_against_the_same_run_in_process():
    def verdict(isolated, in_process, exit_code=0):
        figures = [suite.SuiteFigure(suite.ISOLATED, command="…", baseline=1.0, seconds=isolated, returncode=exit_code),
                   suite.SuiteFigure(suite.IN_PROCESS, command="…", baseline=1.0, seconds=in_process)]
        return [v for v in targets.evaluate_suite(figures) if "crash isolation" in v.target][0]

    assert verdict(82.0, 80.0).passed and "1.02× (82.0 s against 80.0 s, exit 0 and 0)" in verdict(82.0, 80.0).measured
    assert not verdict(90.0, 80.0).passed, "over 1.1×"
    assert not verdict(81.0, 80.0, exit_code=1).passed, "a right sync failing isolated is no measurement"


def _machine():
    from benchmarks import machine

    return machine.machine()


def test_app_mode_figures_are_per_tick_against_the_apps_own_tick():
    app = Path(__file__).resolve().parent.parent / "benchmarks" / "apps" / f"boxes_{backends.NAME}.py"
    figure = app_mode.measure("boxes", app, {"BENCH_BODIES": "27", "BENCH_TICKS": "10"}, repeats=1, ticks=20)
    assert figure.ticks == 10  # the app ends itself
    assert figure.baseline > 0 and figure.record > 0 and figure.judge > 0
    assert figure.seconds == pytest.approx(figure.record + figure.judge) and figure.ratio == figure.seconds / figure.baseline
    text = report.markdown(Results(options=Options(parts=()), machine=_machine(), started="now", apps=[figure]))
    assert "**App mode**" in text and "| boxes | 10 |" in text
    assert [name for name, _, _ in app_mode.apps(backends.NAME)][-1].startswith("1,000 boxes in one actor")


@pytest.mark.full("times two whole app runs: a benchmark of the kit, not discrimination")
def test_a_failing_robots_verdict_is_timed_against_the_passing_one():
    """The figure is the failing verdict's wall time over the passing one's, measured in the same run; the
    report says the target (issue 29: at most twice)."""
    from benchmarks.app_mode import VerdictFigure

    apps = Path(__file__).resolve().parent / "apps"
    figure = app_mode.verdict_cost("box", apps / f"box_{backends.NAME}.py", apps / f"box_{backends.NAME}.py", repeats=1)
    assert figure.seconds > 0 and figure.baseline > 0 and figure.ratio == figure.seconds / figure.baseline
    text = report.markdown(Results(options=Options(parts=()), machine=_machine(), started="now",
                                   verdict_costs=[VerdictFigure("a robot", 3.0, 2.0)]))
    assert "**A failing robot's verdict**" in text and "| a robot | 3.0 s | 2.0 s | 1.5" in text
    assert all(right.exists() and wrong.exists() for _, right, wrong in app_mode.verdict_pairs(backends.NAME))
