"""``run [--sync SPEC] [pytest args]``: the conformance checks, with a verdict per scene."""

from __future__ import annotations

import subprocess
import sys

from conformance import validation

NAME = "run"
HELP = "run the conformance checks (extra arguments go to pytest)"
TAKES_PYTEST_ARGS = True


def add_arguments(parser) -> None:
    # read in run(), not by the command line's common code: an empty value is refused with `error:`
    parser.add_argument("--sync", dest="sync_given", default=None, metavar="SPEC",
                        help="sync implementation (short name or module:attribute; default: the ini's "
                        "conformance_sync, else $CONFORMANCE_SYNC, else reference)")


def run(args, extra: list[str]) -> int:
    # Only a --sync given here is passed on: pytest's plug-in then finds the rest as it always does (the
    # ini's conformance_sync, then $CONFORMANCE_SYNC, then reference), so `run` checks what pytest would.
    given = [] if args.sync_given is None else ["--sync", validation.resolve_sync(args.sync_given)]
    if not given:
        validation.resolve_sync(None)  # a $CONFORMANCE_SYNC that is set is refused here, in one line, if empty
    # A pytest process of its own: in this one the kit is already imported, too late for pytest to
    # rewrite its asserts. The plug-in starts (and stops) a virtual display if it needs one, and
    # checks the other options (pytest's own usage errors exit with status 4).
    argv = [sys.executable, "-m", "pytest", "--pyargs", "conformance", "-p", "no:cacheprovider", *given, *extra]
    from conformance.backends.display import dies_with_this_process

    # However this process ends (SIGTERM from a cancelled CI job, SIGKILL, Ctrl-C), pytest gets
    # SIGTERM and stops its display on the way out: nothing is left running.
    with subprocess.Popen(argv, preexec_fn=dies_with_this_process()) as pytest_run:
        return _wait_through_ctrl_c(pytest_run)


def _wait_through_ctrl_c(child: subprocess.Popen) -> int:
    """The child's exit status. Ctrl-C reaches the child too (the terminal signals the whole foreground
    group), and pytest answers it with its summary and the per-scene table: this process waits for
    that instead of dying with a traceback and taking the child down mid-sentence. A second Ctrl-C
    stops the child at once."""
    interrupted = False
    while True:
        try:
            return child.wait()
        except KeyboardInterrupt:
            if interrupted:
                child.terminate()
            interrupted = True
