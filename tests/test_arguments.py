"""Bad arguments are refused, never silently replaced, each with one sentence naming the argument, its
value and its type, and saying what it should be; the command line exits with status 2 and writes
nothing, the pytest plugin stops with a usage error before anything runs.

Every rule is tried as a new user would meet it (the command line, an option, an ini line, an
environment variable CI set from an unset variable), and the validators themselves over many values.
"""

from __future__ import annotations

import contextlib
import io
import math
import os
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conformance import cli, sync, validation
from conformance.errors import BadArgument


def _cli(argv, cwd: Path, env: dict | None = None) -> tuple[int, str, str]:
    """Run the command line in this process from ``cwd``: (status, stdout, stderr)."""
    out, err = io.StringIO(), io.StringIO()
    old_cwd, old_env = os.getcwd(), dict(os.environ)
    os.chdir(cwd)
    os.environ.pop(sync.ENV_VAR, None)
    os.environ.update(env or {})
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                status = cli.main(argv)
            except SystemExit as exc:  # argparse's own refusals
                status = exc.code
    finally:
        os.chdir(old_cwd)
        os.environ.clear()
        os.environ.update(old_env)
    return status, out.getvalue(), err.getvalue()


def _files(root: Path) -> set[str]:
    return {str(p.relative_to(root)) for p in root.rglob("*")}


def _assert_refused(argv, tmp_path: Path, *needles: str, env: dict | None = None) -> str:
    before = _files(tmp_path)
    status, out, err = _cli(argv, tmp_path, env)
    assert status == 2, (status, out, err)
    lines = [line for line in err.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: "), err  # one paragraph, no traceback
    for needle in needles:
        assert needle in lines[0], f"{needle!r} not in {lines[0]!r}"
    assert _files(tmp_path) == before, "something was written"
    assert "wrote" not in out
    return lines[0]


# -- the command line, rule by rule ----------------------------------------------------------------

@pytest.mark.parametrize("argv, needles", [
    (["render", "chain", "--step", "-3"], ["--step=-3 (int), but should be a whole number from 0 to 100000"]),
    (["render", "chain", "--step", "100001"], ["--step=100001 (int)", "from 0 to 100000"]),
    (["render", "chain", "--step", "2.5"], ["--step='2.5' (str), but should be a whole number"]),
    (["render", "chain", "--size", "0", "0"], ["--size W=0 (int), but should be a whole number from 1 to 8192"]),
    (["render", "chain", "--size", "100", "8193"], ["--size H=8193 (int)", "from 1 to 8192"]),
    (["render", "chain", "--size", "100", "x"], ["--size H='x' (str)"]),
    (["render", "chain", "--sync", ""], ["--sync='' (str), but should be a short name", "leave --sync out"]),
    (["render", "chain", "--sync", "  "], ["--sync='  ' (str)"]),
    (["render", "chain", "--out", "chain.jpg"], ["--out='chain.jpg' (str), but should be the path of a file to write "
                                                 "ending in .png"]),
    (["render", "chain", "--out", ""], ["--out='' (str)"]),
    (["render", "chain", "free_fall", "--out", "x.png"], ["--out='x.png' (str), but should be left out with 2 scenes",
                                                          "--out-dir"]),
    (["render", "chain", "--out", "x.png", "--out-dir", "d"], ["--out-dir='d' (str), but should be left out with --out"]),
    (["render", "chain", "--out-dir", ""], ["--out-dir='' (str), but should be a directory"]),
    (["render", "free_fall", "--frames", "0:5"], ["--frames='0:5' (str), but should be given only with --gif"]),
    (["check", "free_fall", "--frames", "-1"], ["--frames=-1 (int), but should be a whole number from 0 to 100000"]),
    (["check", "free_fall", "--sync", ""], ["--sync='' (str)"]),
    (["run", "--sync", ""], ["--sync='' (str)"]),
    (["regen", "free_fall", "--golden-dir", ""], ["--golden-dir='' (str), but should be a directory"]),
])
def test_command_line_argument_is_refused(tmp_path, argv, needles):
    _assert_refused(argv, tmp_path, *needles)


@pytest.mark.parametrize("command", [["render", "chain"], ["check", "free_fall"], ["run"]])
def test_empty_sync_variable_is_refused_not_read_as_the_default(tmp_path, command):
    # What `CONFORMANCE_SYNC: ${{ vars.SYNC }}` gives in CI when nobody set SYNC: a green run of the
    # reference sync would check nothing of the user's.
    _assert_refused(command, tmp_path, "CONFORMANCE_SYNC='' (str), but should be a short name",
                    "unset it for the default", env={sync.ENV_VAR: ""})


def test_unset_sync_variable_still_means_reference(tmp_path):
    status, out, err = _cli(["check", "free_fall", "--frames", "1"], tmp_path)
    assert status == 0 and "PASS free_fall with sync 'reference'" in out, err


def test_paths_the_kit_cannot_write_are_refused(tmp_path):
    (tmp_path / "a_file").write_text("x")
    (tmp_path / "a_dir.png").mkdir()
    _assert_refused(["render", "chain", "--out", "a_file/x.png"], tmp_path, "--out='a_file/x.png' (str)",
                    "is a file, not a directory")
    _assert_refused(["render", "chain", "--out", "a_dir.png"], tmp_path, "--out='a_dir.png' (str)", "it is a directory")
    _assert_refused(["render", "chain", "--out-dir", "a_file"], tmp_path, "--out-dir='a_file' (str)", "it is a file")
    _assert_refused(["regen", "free_fall", "--golden-dir", "a_file"], tmp_path, "--golden-dir='a_file' (str)",
                    "it is a file")


@pytest.mark.parametrize("frames, needle", [
    ("5:2", "--frames='5:2' (str), but should be 'B', 'A:B' or 'A:B:S' with whole numbers 0 <= A <= B and S >= 1"),
    ("-1:5", "--frames='-1:5' (str)"),
    ("0:5:0", "--frames='0:5:0' (str)"),
    ("a:b", "--frames='a:b' (str)"),
    ("", "--frames='' (str)"),
    ("0:1000", "--frames='0:1000' (str), but should be at most 500 frames, not 1001; thin them out, e.g. 0:1000:3"),
    ("0:200000:1000", "--frames='0:200000:1000' (str), but should be a range ending at frame 100000 at the latest"),
])
def test_animation_frames_are_checked(tmp_path, frames, needle):
    # `--frames=-1:5`: written apart, argparse would take "-1:5" for an option
    _assert_refused(["render", "free_fall", "--gif", "a.gif", f"--frames={frames}"], tmp_path, needle)


@pytest.mark.parametrize("argv, needle", [
    (["render", "free_fall", "--gif", "a.png"], "--gif='a.png' (str), but should be the path of a file to write ending "
                                                "in .gif or .mp4"),
    (["render", "free_fall", "--gif", ""], "--gif='' (str)"),
    (["render", "free_fall", "--gif", "a.gif", "--step", "3"], "--step='3' (str), but should be left out with --gif"),
    (["render", "free_fall", "--gif", "a.gif", "--out", "a.png"], "--out='a.png' (str), but should be left out with --gif"),
    (["render", "free_fall", "chain", "--gif", "a.gif"], "scene='free_fall chain' (str), but should be one scene name"),
    (["render", "free_fall", "--gif", "a.gif", "--frames", "0:100", "--size", "4000", "4000"],
     "--frames='0:100' (str), but should be at most 100,000,000 pixels in all"),
])
def test_animation_arguments_are_checked(tmp_path, argv, needle):
    _assert_refused(argv, tmp_path, needle)


def test_json_arguments_are_checked_as_before(tmp_path):
    _assert_refused(["render", "free_fall", "--params", "[1]"], tmp_path, "is a JSON list, but should be an object")
    _assert_refused(["check", "free_fall", "--events", "{"], tmp_path, "is not a list of events")


# -- the pytest plugin ------------------------------------------------------------------------------

RUN = ["--pyargs", "conformance", "-p", "no:cacheprovider", "-k", "test_vertices_match_poses_every_frame and free_fall"]


def _assert_usage_error(result, *needles: str) -> None:
    assert result.ret == pytest.ExitCode.USAGE_ERROR, result.stdout.str()[-2000:]
    err = result.stderr.str()
    for needle in needles:
        assert needle in err, f"{needle!r} not in:\n{err}"
    assert "Traceback" not in err and "passed" not in result.stdout.str()


@pytest.mark.parametrize("args, needle", [
    (["--sync", ""], "--sync='' (str), but should be a short name"),
    (["--conformance-atol", "nan"], "--conformance-atol=nan (float), but should be a finite number >= 0"),
    (["--conformance-size-rtol", "inf"], "--conformance-size-rtol=inf (float), but should be a finite number >= 0"),
    (["--conformance-position-rtol=-1e-7"], "--conformance-position-rtol=-1e-07 (float)"),
    (["--conformance-normal-angle", "small"], "--conformance-normal-angle='small' (str)"),
    (["--conformance-atol", ""], "--conformance-atol='' (str)"),
    (["--conformance-report", ""], "--conformance-report='' (str), but should be the path of a JSON file to write"),
    (["--conformance-report", "no/such/dir/r.json"], "make the directory"),
    (["--conformance-report", "."], "--conformance-report='.' (str)"),
    (["--conformance-summary", ""], "--conformance-summary='' (str), but should be the path of a file to write"),
    (["--conformance-summary", "."], "--conformance-summary='.' (str), but should be the path of a file to write; it is a directory"),
    (["--conformance-image-tolerance", "loose"], "--conformance-image-tolerance='loose' (str), but should be one of "
                                                 "auto, same-renderer, other-renderer"),
    (["--conformance-results", ""], "--conformance-results='' (str), but should be a directory"),
    (["--conformance-golden-dir", ""], "--conformance-golden-dir='' (str)"),
])
def test_plugin_option_is_a_usage_error(pytester, args, needle):
    _assert_usage_error(pytester.runpytest(*RUN, *args), needle)


@pytest.mark.parametrize("line, needle", [
    ("conformance_sync =", "ini conformance_sync='' (str), but should be a short name"),
    ("conformance_atol = inf", "ini conformance_atol=inf (float)"),
    ("conformance_size_rtol =", "ini conformance_size_rtol='' (str)"),
    ("conformance_report =", "ini conformance_report='' (str)"),
    ("conformance_summary =", "ini conformance_summary='' (str), but should be the path of a file to write"),
    ("conformance_image_tolerance =", "ini conformance_image_tolerance='' (str)"),
    ("conformance_results =", "ini conformance_results='' (str)"),
])
def test_ini_value_present_but_bad_is_a_usage_error(pytester, line, needle):
    pytester.makeini(f"[pytest]\n{line}\n")
    _assert_usage_error(pytester.runpytest(*RUN), needle)


def test_empty_sync_variable_is_a_usage_error(pytester, monkeypatch):
    monkeypatch.setenv(sync.ENV_VAR, "")
    _assert_usage_error(pytester.runpytest(*RUN), "CONFORMANCE_SYNC='' (str)", "unset it for the default")


def test_a_step_summary_the_kit_cannot_write_is_a_usage_error(pytester, monkeypatch):
    monkeypatch.setenv(validation.STEP_SUMMARY_VAR, str(pytester.path))
    _assert_usage_error(pytester.runpytest(*RUN), f"GITHUB_STEP_SUMMARY={str(pytester.path)!r} (str)", "it is a directory")


def test_an_unset_or_empty_step_summary_is_none_and_a_file_is_taken():
    """GitHub's variable, not the kit's: empty turns the step summary off for one run, rather than being refused."""
    assert validation.step_summary({}) is None and validation.step_summary({validation.STEP_SUMMARY_VAR: ""}) is None
    assert validation.step_summary({validation.STEP_SUMMARY_VAR: "/tmp/step_summary"}) == Path("/tmp/step_summary")


def test_good_tolerances_are_used(pytester):
    result = pytester.runpytest(*RUN, "-v", "--conformance-atol", "2e-9", "--conformance-normal-angle", "0.001")
    assert result.ret == 0, result.stdout.str()[-2000:]
    result.stdout.fnmatch_lines(["*tolerance*"])


# -- the validators over many values -----------------------------------------------------------------

@given(st.integers(max_value=-1) | st.integers(min_value=validation.MAX_STEPS + 1))
def test_whole_number_out_of_range(n):
    with pytest.raises(BadArgument, match=rf"^--step={n} \(int\), but should be a whole number from 0 to 100000\.$"):
        validation.whole_number("--step", str(n), high=validation.MAX_STEPS)


@given(st.integers(min_value=0, max_value=validation.MAX_STEPS))
def test_whole_number_in_range(n):
    assert validation.whole_number("--step", str(n), high=validation.MAX_STEPS) == n
    assert validation.whole_number("--step", n, high=validation.MAX_STEPS) == n


@given(st.text().filter(lambda s: not s.strip().lstrip("+-").isdigit()))
def test_whole_number_not_a_number(text):
    with pytest.raises(BadArgument) as info:
        validation.whole_number("--frames", text)
    assert str(info.value).startswith(f"--frames={text!r} (str), but should be")


@given(st.floats(allow_nan=True, allow_infinity=True).filter(lambda x: not (math.isfinite(x) and x >= 0)))
def test_tolerance_not_finite_or_negative(x):
    for given_as in (x, repr(x)):
        with pytest.raises(BadArgument) as info:
            validation.finite_non_negative("--conformance-atol", given_as)
        assert str(info.value).startswith(f"--conformance-atol={x!r} (float), but should be a finite number >= 0")


@given(st.floats(min_value=0, allow_infinity=False))
def test_tolerance_accepted(x):
    assert validation.finite_non_negative("--conformance-atol", repr(x)) == x


@given(st.integers(-5, 10), st.integers(-5, 10))
def test_image_size(w, h):
    if w >= 1 and h >= 1:
        assert validation.image_size("--size", [str(w), str(h)]) == (w, h)
    else:
        with pytest.raises(BadArgument, match=rf"^--size {'W' if w < 1 else 'H'}=-?\d+ \(int\)"):
            validation.image_size("--size", [str(w), str(h)])


@given(st.integers(0, 3000), st.integers(0, 3000), st.integers(0, 20))
def test_frame_range(a, b, s):
    text = f"{a}:{b}:{s}"
    valid = b >= a and s >= 1 and len(range(a, b + 1, max(s, 1))) <= validation.MAX_ANIMATION_FRAMES
    if valid:
        assert validation.frame_range("--frames", text) == range(a, b + 1, s)
    else:
        with pytest.raises(BadArgument, match=rf"^--frames='{text}' \(str\), but should be"):
            validation.frame_range("--frames", text)


@settings(max_examples=50)
@given(st.text(alphabet=" \t\n", max_size=3))
def test_blank_sync_is_refused_wherever_it_comes_from(blank):
    with pytest.raises(BadArgument, match=r"^--sync="):
        validation.resolve_sync(blank, None, {})
    with pytest.raises(BadArgument, match=r"^ini conformance_sync="):
        validation.resolve_sync(None, blank, {})
    with pytest.raises(BadArgument, match=r"^CONFORMANCE_SYNC="):
        validation.resolve_sync(None, None, {"CONFORMANCE_SYNC": blank})


def test_sync_precedence_and_default():
    assert validation.resolve_sync(None, None, {}) == "reference"
    assert validation.resolve_sync(None, None, {"CONFORMANCE_SYNC": "guide"}) == "guide"
    assert validation.resolve_sync(None, "guide-joint", {"CONFORMANCE_SYNC": "guide"}) == "guide-joint"
    assert validation.resolve_sync(" guide-actor ", "guide-joint", {"CONFORMANCE_SYNC": "guide"}) == "guide-actor"


def test_the_validators_know_the_kit_s_own_names():
    from conformance import plugin

    assert set(validation.TOLERANCE_OPTIONS) == set(plugin._TOLERANCE_OPTIONS)


def test_validators_for_the_other_commands(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert validation.positive_int("--jobs", "4", high=validation.MAX_JOBS) == 4
    with pytest.raises(BadArgument, match=r"^--jobs=0 \(int\), but should be a whole number from 1 to 256\.$"):
        validation.positive_int("--jobs", "0", high=validation.MAX_JOBS)
    assert validation.module_name("--wrong", "tests.wrong_syncs") == "tests.wrong_syncs"
    with pytest.raises(BadArgument, match=r"^--wrong='tests/wrong_syncs.py' \(str\), but should be a dotted module name"):
        validation.module_name("--wrong", "tests/wrong_syncs.py")
    with pytest.raises(BadArgument, match=r"^--readme='nope.md' \(str\), but should be an existing file; it does not exist"):
        validation.existing_file("--readme", "nope.md")
    assert validation.sync_spec("SPEC", "guide") == "guide"
    with pytest.raises(BadArgument, match=r"^SPEC='' \(str\)"):
        validation.sync_spec("SPEC", "")


@pytest.mark.parametrize("text, ok", [("2/4", (2, 4)), ("1/1", (1, 1)), ("0/4", None), ("5/4", None), ("2", None),
                                      ("a/b", None), ("", None)])
def test_shard(text, ok):
    if ok:
        assert validation.shard("--shard", text) == ok
    else:
        with pytest.raises(BadArgument, match=rf"^--shard={text!r} \(str\), but should be K/N"):
            validation.shard("--shard", text)


def test_argparse_type_gives_argparse_s_one_line_error(capsys):
    import argparse

    parser = argparse.ArgumentParser(prog="verdicts")
    parser.add_argument("--jobs", type=validation.argparse_type(validation.positive_int, "--jobs",
                                                                high=validation.MAX_JOBS))
    assert parser.parse_args(["--jobs", "3"]).jobs == 3
    with pytest.raises(SystemExit) as info:
        parser.parse_args(["--jobs", "0"])
    assert info.value.code == 2
    assert "error: argument --jobs: --jobs=0 (int), but should be a whole number from 1 to 256." in capsys.readouterr().err


def test_what_follows_a_double_dash_goes_to_pytest_as_options(tmp_path):
    # `run -- -k X`: pytest must get `-k X`, not `-- -k X` (which makes "-k" a file to collect).
    import subprocess
    import sys

    done = subprocess.run([sys.executable, "-m", "conformance", "run", "--", "-k", "test_no_stale_goldens", "--collect-only",
                           "-q"], cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    assert "1/" in done.stdout and "tests collected" in done.stdout, done.stdout[-1000:]
