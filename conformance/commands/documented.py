"""``documented``: pybullet's behaviour measured against its documentation, as a markdown table."""

from __future__ import annotations

from conformance.commands.common import emit, page_header
from conformance.validation import argparse_type, file_to_write

NAME = "documented"
HELP = "measure pybullet against its documentation and print the table"


def add_arguments(parser) -> None:
    parser.add_argument("--out", type=argparse_type(file_to_write, "--out"), default=None, help="also write the markdown here")


def run(args, extra) -> int:
    from conformance.checks import documented

    emit(documented.table(), args.out, page_header(args))
    return 0
