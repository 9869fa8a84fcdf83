"""``scenes [-v]``: the reference scenes and their parameters."""

from __future__ import annotations

NAME = "scenes"
HELP = "list the reference scenes"


def add_arguments(parser) -> None:
    parser.add_argument("-v", "--verbose", action="store_true", help="also list parameters and defaults")


def run(args, extra) -> int:
    from conformance import scenes

    for name, spec in scenes.SCENES.items():
        print(f"{name}  [{spec.origin}, {spec.steps} steps]  {spec.title}: {spec.description}")
        if args.verbose:
            for key, value in spec.defaults.items():
                print(f"    {key} = {value!r}")
    return 0
