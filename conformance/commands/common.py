"""What several commands share: JSON scene parameters, printing a table, filling a README block."""

from __future__ import annotations

import json
from pathlib import Path

from conformance.errors import ConformanceError
from conformance.files import write_atomically

__all__ = ["add_backend_run_arguments", "add_tolerance_arguments", "emit", "params", "replace_block", "tolerance_of"]

#: The vertex tolerance's fields a command takes, spelled as the pytest plug-in's ``--conformance-…``
#: options, so that a reproduce line carries the tolerance its run used (``check``, ``render``).
TOLERANCES = ("size_rtol", "position_rtol", "atol", "normal_angle")


def add_tolerance_arguments(parser) -> None:
    for name in TOLERANCES:
        parser.add_argument(f"--conformance-{name.replace('_', '-')}", dest=name, default=None, metavar="X",
                            help=f"the vertex checks' {name} (default: the kit's)")


def tolerance_of(args):
    """The tolerance the command's options give (the kit's default where they give none)."""
    import dataclasses

    from conformance import validation
    from conformance.judge.tolerances import DEFAULT

    values = {name: getattr(args, name, None) for name in TOLERANCES}  # a namespace made in code may lack them
    given = {name: validation.finite_non_negative(f"--conformance-{name.replace('_', '-')}", value)
             for name, value in values.items() if value is not None}
    return dataclasses.replace(DEFAULT, **given)


def params(text: str | None) -> dict:
    """``--params`` as a dict of scene parameters (JSON lists become tuples)."""
    if not text:
        return {}
    try:
        value = json.loads(text)
    except json.JSONDecodeError as exc:
        raise ConformanceError(f"--params={text!r} is not JSON ({exc.msg}); write e.g. --params '{{\"rows\": 3}}'") from None
    if not isinstance(value, dict):
        raise ConformanceError(f"--params={text!r} is a JSON {type(value).__name__}, but should be an object of scene parameters")
    return {k: tuple(v) if isinstance(v, list) else v for k, v in value.items()}


def add_backend_run_arguments(parser) -> None:
    """``--json`` and ``--beside``, of ``verdicts`` and ``kill-rate``: keep this backend's run, and put
    another backend's kept run beside it in the README (the two FURYs live in two environments)."""
    from conformance.validation import argparse_type, existing_file, file_to_write

    parser.add_argument("--json", type=argparse_type(file_to_write, "--json"), default=None,
                        help="also keep this run's outcomes here, to be put --beside the other backend's")
    parser.add_argument("--beside", action="append", type=argparse_type(existing_file, "--beside"), default=[],
                        help="a run another backend kept with --json: the README table shows both, side by side")


def emit(text: str, out: str | None) -> None:
    """Print ``text``; also write it to ``out`` if given."""
    print(text)
    if out:
        write_atomically(Path(out), (text + "\n").encode("utf-8"))


def replace_block(path: str, name: str, text: str) -> None:
    """Put ``text`` between the lines ``<!-- conformance:NAME -->`` and ``<!-- /conformance:NAME -->``
    of the markdown file ``path`` (written whole, atomically)."""
    start, end = f"<!-- conformance:{name} -->", f"<!-- /conformance:{name} -->"
    target = Path(path)
    try:
        old = target.read_text(encoding="utf-8")
    except OSError as exc:
        raise ConformanceError(f"--readme {path!r}: cannot read it ({exc.strerror})") from None
    if old.count(start) != 1 or old.count(end) != 1 or old.index(start) > old.index(end):
        raise ConformanceError(f"--readme {path!r}: needs one line {start!r} followed by one line {end!r} "
                               "around the place the table goes")
    new = old[:old.index(start) + len(start)] + "\n" + text.strip() + "\n" + old[old.index(end):]
    write_atomically(target, new.encode("utf-8"))
