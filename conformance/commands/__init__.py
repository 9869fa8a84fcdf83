"""One module per command of ``python -m conformance``; :mod:`conformance.cli` assembles them.

Each module defines ``NAME``, ``HELP``, ``add_arguments(parser)`` and ``run(args, extra) -> int``
(the exit status), and ``TAKES_PYTEST_ARGS = True`` if unknown arguments go on to pytest.
"""

#: The commands in the order ``--help`` lists them.
MODULES = ["run", "app", "app_table", "scenes", "render", "check", "compare", "verdicts", "kill_rate", "mutants", "tolerance_use", "precision", "zoo", "confusion", "regen", "bench", "documented"]
