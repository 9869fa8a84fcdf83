"""Every option, ini value, environment variable and command-line argument the kit takes, checked in
one place.

Each validator takes the name the user wrote (``--step``, ``ini conformance_atol``,
``CONFORMANCE_SYNC``) and the value as given, and returns the value to use or raises
:class:`~conformance.errors.BadArgument` with one sentence in the style of Hypothesis: the name, the
value, its type, and what it should be (``--step=-3 (int), but should be a whole number from 0 to
100000.``). A value is never silently replaced: an empty value given on purpose (``--sync ''``, a
``CONFORMANCE_SYNC`` that CI set from an unset variable, an ini key with nothing after ``=``) is
refused, and only a value that was not given at all takes the default.

Nothing here writes anything: a path is checked for whether it *could* be written, so a refused
argument leaves the disk as it was.

:func:`plugin_options` reads and checks every option of the pytest plugin at once (the plugin calls
it when pytest is configured, so a bad value stops the run before anything is collected);
:func:`resolve_sync` is the one rule for which sync is under test.
"""

from __future__ import annotations

import math
import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping, Sequence

from conformance.errors import BadArgument
from conformance.implementations import SHORT_NAMES

__all__ = [
    "DEFAULT_RESULTS",
    "DEFAULT_SYNC",
    "IMAGE_TOLERANCE_CHOICES",
    "ISOLATION_CHOICES",
    "MAX_ANIMATION_FRAMES",
    "MAX_ANIMATION_PIXELS",
    "MAX_IMAGE_SIDE",
    "MAX_JOBS",
    "MAX_STEPS",
    "STEP_SUMMARY_VAR",
    "SYNC_ENV_VAR",
    "TOLERANCE_OPTIONS",
    "PluginOptions",
    "absent",
    "animation_path",
    "animation_pixels",
    "argparse_type",
    "choice",
    "directory_to_write",
    "existing_directory",
    "existing_file",
    "file_to_write",
    "finite_non_negative",
    "frame_range",
    "image_size",
    "module_name",
    "plugin_option",
    "plugin_options",
    "positive_int",
    "report_path",
    "resolve_sync",
    "shard",
    "step_summary",
    "sync_spec",
    "whole_number",
]

#: Steps a command may run a scene for: ten times the longest scene (``tumbling``, 10,000 steps).
MAX_STEPS = 100_000
#: The largest picture side: VTK's off-screen windows and Xvfb's screen allow more, memory does not.
MAX_IMAGE_SIDE = 8192
#: Pictures in one animation: a few hundred is already a 30-second GIF of tens of megabytes.
MAX_ANIMATION_FRAMES = 500
#: Pixels in all the pictures of one animation (frames × width × height), which are held in memory.
MAX_ANIMATION_PIXELS = 100_000_000
#: pytest processes at a time for ``verdicts`` and ``kill-rate``.
MAX_JOBS = 256

#: The environment variable that names the sync when neither --sync nor the ini does (``conformance.sync.ENV_VAR``).
SYNC_ENV_VAR = "CONFORMANCE_SYNC"
DEFAULT_SYNC = "reference"
#: GitHub Actions' file of a step's Markdown summary, shown on the run's page: the kit adds its summary there.
STEP_SUMMARY_VAR = "GITHUB_STEP_SUMMARY"
#: ``--conformance-isolation``: a serial run in a worker process of its own (``conformance.session.isolation``).
ISOLATION_CHOICES = ("auto", "process", "none")

IMAGE_TOLERANCE_CHOICES = ("auto", "same-renderer", "other-renderer")

#: The plugin's tolerance options: ``--conformance-NAME`` and ini ``conformance_NAME`` (dashes, underscores).
TOLERANCE_OPTIONS = ("size_rtol", "position_rtol", "atol", "normal_angle")
#: Where the image checks put pictures, records and report.html unless told otherwise.
DEFAULT_RESULTS = "conformance-results"


def _refuse(name: str, value: Any, should: str, hint: str = "") -> BadArgument:
    """The one message shape: ``NAME=VALUE (TYPE), but should be SHOULD[; HINT].``"""
    hint = f"; {hint}" if hint else ""
    return BadArgument(f"{name}={value!r} ({type(value).__name__}), but should be {should}{hint}.")


# -- numbers ---------------------------------------------------------------------------------------

def _as_int(value: Any) -> Any:
    """``value`` as an int if it is one, or a string that spells one; otherwise ``value`` unchanged."""
    if isinstance(value, bool):
        return value
    if isinstance(value, int):
        return value
    if isinstance(value, str) and re.fullmatch(r"\s*[+-]?\d+\s*", value):
        return int(value)
    return value


def whole_number(name: str, value: Any, *, low: int = 0, high: int | None = None) -> int:
    """An int from ``low`` to ``high`` (inclusive), given as an int or a string that spells one."""
    number = _as_int(value)
    should = f"a whole number from {low} to {high}" if high is not None else f"a whole number >= {low}"
    if not isinstance(number, int) or isinstance(number, bool) or number < low or (high is not None and number > high):
        raise _refuse(name, number, should)
    return number


def positive_int(name: str, value: Any, *, high: int | None = None) -> int:
    """A whole number >= 1 (a count of processes, a stride)."""
    return whole_number(name, value, low=1, high=high)


def finite_non_negative(name: str, value: Any) -> float:
    """A finite float >= 0, given as a number or a string that spells one (a tolerance)."""
    number = value
    if isinstance(value, str):
        try:
            number = float(value)
        except ValueError:
            pass  # refused below, shown as the string it is
    if isinstance(number, bool) or not isinstance(number, (int, float)) or not math.isfinite(number) or number < 0:
        raise _refuse(name, number, "a finite number >= 0")
    return float(number)


def image_size(name: str, values: Sequence[Any]) -> tuple[int, int]:
    """A picture's (width, height): two whole numbers from 1 to :data:`MAX_IMAGE_SIDE`."""
    if len(values) != 2:
        raise _refuse(name, tuple(values), "two whole numbers, the width and the height")
    return tuple(whole_number(f"{name} {side}", v, low=1, high=MAX_IMAGE_SIDE)  # type: ignore[return-value]
                 for side, v in zip("WH", values))


def frame_range(name: str, text: Any, *, limit: int = MAX_ANIMATION_FRAMES) -> range:
    """``B``, ``A:B`` or ``A:B:S``: frames A to B *inclusive* every S (A defaults to 0, S to 1), as in
    ``check --frames N``, which replays frames 0 to N. At most ``limit`` frames, none past
    :data:`MAX_STEPS`."""
    shape = "'B', 'A:B' or 'A:B:S' with whole numbers 0 <= A <= B and S >= 1 (frames A to B every S), e.g. 0:120:4"
    if not isinstance(text, str) or not re.fullmatch(r"\s*\d+\s*(:\s*\d+\s*(:\s*\d+\s*)?)?", text):
        raise _refuse(name, text, shape)
    parts = [int(p) for p in text.split(":")]
    if len(parts) == 1:
        parts = [0, parts[0]]
    start, stop, stride = (parts + [1])[:3]
    if stop < start or stride < 1:
        raise _refuse(name, text, shape)
    if stop > MAX_STEPS:
        raise _refuse(name, text, f"a range ending at frame {MAX_STEPS} at the latest")
    frames = range(start, stop + 1, stride)
    if len(frames) > limit:
        every = math.ceil((stop - start + 1) / limit)
        raise _refuse(name, text, f"at most {limit} frames, not {len(frames)}", f"thin them out, e.g. {start}:{stop}:{every}")
    return frames


def animation_pixels(name: str, value: Any, frames: range, size: tuple[int, int]) -> None:
    """Refuse an animation whose pictures, all held in memory, exceed :data:`MAX_ANIMATION_PIXELS`."""
    pixels = len(frames) * size[0] * size[1]
    if pixels > MAX_ANIMATION_PIXELS:
        raise _refuse(name, value, f"at most {MAX_ANIMATION_PIXELS:,} pixels in all, not {len(frames)} pictures of "
                      f"{size[0]}x{size[1]} ({pixels:,})", "take fewer frames (a larger S) or a smaller --size")


def absent(name: str, value: Any, should: str, why: str = "") -> None:
    """Refuse ``name`` if it was given (``value`` is not None) where it cannot apply; ``should`` says
    when it can (``"left out with --gif"``)."""
    if value is not None:
        raise _refuse(name, value, should, why)


def shard(name: str, value: Any) -> tuple[int, int]:
    """``K/N``: the K-th of N shares of the checks, 1 <= K <= N (``--shard``)."""
    match = re.fullmatch(r"\s*(\d+)\s*/\s*(\d+)\s*", value) if isinstance(value, str) else None
    if not match or not 1 <= int(match[1]) <= int(match[2]):
        raise _refuse(name, value, "K/N with whole numbers 1 <= K <= N", "e.g. --shard 2/4 for the second of four CI jobs")
    return int(match[1]), int(match[2])


# -- names -----------------------------------------------------------------------------------------

def choice(name: str, value: Any, choices: Sequence[str]) -> str:
    """One of ``choices``, exactly."""
    if value not in choices:
        raise _refuse(name, value, f"one of {', '.join(choices)}")
    return value


def sync_spec(name: str, value: Any, *, default_hint: str = "") -> str:
    """A sync spec as given: a short name or ``module:attribute``, not blank. Whether it loads is
    :func:`conformance.sync.load`'s to say; this refuses only what cannot be a spec at all."""
    should = f"a short name ({', '.join(SHORT_NAMES)}) or 'module:attribute'"
    if not isinstance(value, str) or not value.strip():
        raise _refuse(name, value, should, default_hint)
    return value.strip()


def resolve_sync(option: str | None, ini: Any = None, environ: Mapping[str, str] | None = None,
                 *, option_name: str = "--sync") -> str:
    """The sync under test: ``option`` (``--sync``), else ``ini`` (``conformance_sync``), else
    ``$CONFORMANCE_SYNC``, else ``reference``. ``None`` means not given; anything given, even
    empty, must be a spec (an empty ``CONFORMANCE_SYNC`` is what CI gives for an unset variable, and
    would otherwise run the reference sync: a green run that checked nothing of the user's)."""
    environ = os.environ if environ is None else environ
    if option is not None:
        fallback = ("the ini's conformance_sync" if ini is not None else f"${SYNC_ENV_VAR}" if SYNC_ENV_VAR in environ
                    else f"the default, {DEFAULT_SYNC!r}")
        return sync_spec(option_name, option, default_hint=f"leave {option_name} out for {fallback}")
    if ini is not None:
        fallback = f"${SYNC_ENV_VAR}" if SYNC_ENV_VAR in environ else f"the default, {DEFAULT_SYNC!r}"
        return sync_spec("ini conformance_sync", ini, default_hint=f"remove the line for {fallback}")
    if SYNC_ENV_VAR in environ:
        return sync_spec(SYNC_ENV_VAR, environ[SYNC_ENV_VAR],
                         default_hint=f"set it to a spec, or unset it for the default, {DEFAULT_SYNC!r}")
    return DEFAULT_SYNC


def module_name(name: str, value: Any) -> str:
    """A dotted Python module name (``--wrong``, ``--right`` of ``kill-rate``)."""
    if not isinstance(value, str) or not re.fullmatch(r"[A-Za-z_]\w*(\.[A-Za-z_]\w*)*", value.strip()):
        raise _refuse(name, value, "a dotted module name, e.g. tests.wrong_syncs")
    return value.strip()


# -- paths -----------------------------------------------------------------------------------------

def _path(name: str, value: Any, should: str) -> Path:
    if not isinstance(value, (str, os.PathLike)) or not str(value).strip():
        raise _refuse(name, value, should)
    return Path(value).expanduser()


def _creatable(name: str, value: Any, path: Path, should: str) -> None:
    """Refuse ``path`` unless its nearest existing ancestor is a directory this process may write in."""
    ancestor = path.absolute().parent
    while not ancestor.exists():
        ancestor = ancestor.parent
    if not ancestor.is_dir():
        raise _refuse(name, value, should, f"{str(ancestor)!r} is a file, not a directory")
    if not os.access(ancestor, os.W_OK | os.X_OK):
        raise _refuse(name, value, should, f"this user may not write in {str(ancestor)!r}")


def file_to_write(name: str, value: Any, *, suffixes: Sequence[str] = ()) -> Path:
    """A file the kit may write (atomically, making missing directories): not blank, not a directory,
    ending in one of ``suffixes`` (any case) if given, inside a directory that exists or can be made."""
    ending = f" ending in {' or '.join(suffixes)}" if suffixes else ""
    should = f"the path of a file to write{ending}"
    path = _path(name, value, should)
    if suffixes and path.suffix.lower() not in suffixes:
        raise _refuse(name, value, should)
    if path.is_dir():
        raise _refuse(name, value, should, "it is a directory")
    _creatable(name, value, path, should)
    return path


def directory_to_write(name: str, value: Any) -> Path:
    """A directory the kit may write in: not blank, not a file, existing or possible to make."""
    should = "a directory to write in (made if missing)"
    path = _path(name, value, should)
    if path.exists() and not path.is_dir():
        raise _refuse(name, value, should, "it is a file")
    if not path.exists():
        _creatable(name, value, path / "x", should)
    elif not os.access(path, os.W_OK | os.X_OK):
        raise _refuse(name, value, should, "this user may not write in it")
    return path


def existing_directory(name: str, value: Any, hint: str = "") -> Path:
    """A directory that exists (to read from); ``hint`` says what else the user could do."""
    path = _path(name, value, "an existing directory")
    if not path.is_dir():
        why = "it is a file" if path.exists() else "it does not exist"
        raise _refuse(name, value, "an existing directory", f"{why}{'; ' + hint if hint else ''}")
    return path


def existing_file(name: str, value: Any) -> Path:
    """A file that exists (to read, or to update in place like ``--readme``)."""
    path = _path(name, value, "an existing file")
    if not path.is_file():
        raise _refuse(name, value, "an existing file", "it is a directory" if path.is_dir() else "it does not exist")
    return path


def report_path(name: str, value: Any) -> Path:
    """Where the plugin writes its JSON report: a file (not a directory) in a directory that exists
    (the report is written at the very end of a run, and a run should not fail there)."""
    should = "the path of a JSON file to write, in an existing directory"
    path = _path(name, value, should)
    if path.is_dir():
        raise _refuse(name, value, should, "it is a directory")
    if not path.absolute().parent.is_dir():
        raise _refuse(name, value, should, f"make the directory {str(path.absolute().parent)!r} first")
    if not os.access(path.absolute().parent, os.W_OK | os.X_OK):
        raise _refuse(name, value, should, f"this user may not write in {str(path.absolute().parent)!r}")
    return path


def step_summary(environ: Mapping[str, str] | None = None) -> Path | None:
    """Where a run's Markdown summary goes on GitHub Actions (``$GITHUB_STEP_SUMMARY``), or None. The variable is
    GitHub's, not the kit's: unset or empty, there is none (``GITHUB_STEP_SUMMARY= pytest …`` keeps one run's
    summary off the page); set, it must be a file the kit may write."""
    environ = os.environ if environ is None else environ
    value = environ.get(STEP_SUMMARY_VAR, "")
    return file_to_write(STEP_SUMMARY_VAR, value) if value else None


def animation_path(name: str, value: Any) -> Path:
    """Where ``render --gif`` writes: a ``.gif`` (or ``.mp4``) file to write."""
    return file_to_write(name, value, suffixes=(".gif", ".mp4"))


# -- argparse ----------------------------------------------------------------------------------------

def argparse_type(validator, name: str, **options):
    """An argparse ``type=`` callable from a validator: ``type=argparse_type(positive_int, "--jobs")``.
    argparse then prints its usage and ``argument --jobs: <the validator's sentence>``, exit status 2."""
    import argparse

    def convert(text: str):
        try:
            return validator(name, text, **options)
        except BadArgument as err:
            raise argparse.ArgumentTypeError(str(err)) from None

    convert.__name__ = validator.__name__  # argparse names the type in some messages
    return convert


# -- the pytest plugin's options -------------------------------------------------------------------

@dataclass(frozen=True)
class PluginOptions:
    """Every option of the plugin, checked: what the session runs with."""

    sync: str
    tolerances: dict[str, float]  # only those given; the rest keep conformance.judge.tolerances.DEFAULT
    report: Path | None
    golden_dir: Path | None  # None: each scene's own (conformance.sync.own_scenes.golden_dir)
    image_tolerance: str
    results: Path
    keep_passing: bool
    regen: bool
    summary: Path | None = None  # the Markdown summary's file (--conformance-summary)
    step_summary: Path | None = None  # $GITHUB_STEP_SUMMARY, which the summary is added to


def _given(config, name: str) -> tuple[str, Any]:
    """(the name the user wrote, the value) of option ``conformance_NAME``: the command line first,
    then the ini file; ``(…, None)`` when neither gives it."""
    value = config.getoption(f"conformance_{name}", None)
    if value is not None:
        return f"--conformance-{name.replace('_', '-')}", value
    try:
        return f"ini conformance_{name}", config.getini(f"conformance_{name}")
    except ValueError:  # not an ini setting
        return f"ini conformance_{name}", None


def plugin_option(config, name: str) -> Any:
    """The checked value of the plugin option ``conformance_NAME`` (``None`` when not given); an option
    without a rule here (another module's, which checks it itself) is returned as given."""
    label, value = _given(config, name)
    if value is None:
        return None
    if name in TOLERANCE_OPTIONS or name == "sync_timeout":
        return finite_non_negative(label, value)
    if name == "report":
        return report_path(label, value)
    if name == "summary":
        return file_to_write(label, value)
    if name == "isolation":
        return choice(label, value, ISOLATION_CHOICES)
    if name == "image_tolerance":
        return choice(label, value, IMAGE_TOLERANCE_CHOICES)
    if name == "golden_dir":
        if config.getoption("conformance_regen_golden", False):
            return directory_to_write(label, value)
        return existing_directory(label, value, "give the directory of goldens, or add --regen-golden to make them there")
    if name == "results":
        return directory_to_write(label, value)
    return value


def plugin_options(config) -> PluginOptions:
    """Read and check every option of the plugin (command line first, then ini, then
    ``$CONFORMANCE_SYNC`` for the sync); the first bad one raises :class:`BadArgument`."""
    sync = resolve_sync(config.getoption("conformance_sync", None), config.getini("conformance_sync"))
    tolerances = {name: value for name in TOLERANCE_OPTIONS if (value := plugin_option(config, name)) is not None}
    results = plugin_option(config, "results")
    keep = config.getoption("conformance_keep_passing", None)
    return PluginOptions(
        sync=sync,
        tolerances=tolerances,
        report=plugin_option(config, "report"),
        golden_dir=plugin_option(config, "golden_dir"),
        image_tolerance=plugin_option(config, "image_tolerance") or "auto",
        results=results if results is not None else Path(DEFAULT_RESULTS),
        keep_passing=bool(keep if keep is not None else config.getini("conformance_keep_passing")),
        regen=bool(config.getoption("conformance_regen_golden", False)),
        summary=plugin_option(config, "summary"),
        step_summary=step_summary(),
    )
