"""The kit's benchmarks: what syncing, stepping, rendering and checking cost, never part of the tests.

Run ``python -m conformance bench`` (or ``./kit bench``): it prints markdown tables, and writes JSON
(``--json PATH``) or a README block (``--readme PATH``) only when asked. Every figure is a ratio to a
baseline measured in the same run and process, the best of several rounds, because the machines are
noisy and shared; the table names the machine and the renderer backend in force (the installed
FURY: 0.12 on VTK or 2 on pygfx; ``conformance.backends``), and measures that backend.

* :mod:`.timing` — best-of-N rounds, candidates interleaved;
* :mod:`.grid` — the bench scenes: bricks apart in zero gravity (and chains of links), built like the
  kit's scenes so syncs get a genuine ``World``;
* :mod:`.floor` — the least a sync must do per frame, the baseline of the sync figures;
* :mod:`.backend` — all the bench's renderer-specific code (FURY 0.12/VTK, FURY 2/pygfx): the floor's
  writes, the actor writes the reads table times, the libraries the machine line names;
* :mod:`.syncs` — sync cost per frame against the floor, whole actors and one shared actor;
* :mod:`.reads` — ways of reading poses from pyBullet, against the floor's read;
* :mod:`.pictures` — a render, a golden comparison and the pyBullet-renderer check, against a frame;
* :mod:`.suite` — whole runs of the checks as subprocesses, against the physics of every scene;
* :mod:`.targets` — the team's targets for a sync, judged pass or miss;
* :mod:`.main` and :mod:`.report` — one run, and its tables and JSON.
"""
