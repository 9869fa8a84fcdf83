"""The documented complete example for the backend in force is a right sync implementation: copied out
verbatim, it passes (FURY 2: ``my_sync_fury2.py`` in the README; FURY 0.12: ``my_sync.py`` in
docs/backends.md)."""

from __future__ import annotations

import re
import subprocess
import sys
import tempfile
from pathlib import Path

import background
from conformance import backends
from conformance.backends.display import child_environment, dies_with_this_process

ROOT = Path(__file__).resolve().parent.parent
MODULE, PAGE = {"vtk": ("my_sync", ROOT / "docs" / "backends.md"), "pygfx": ("my_sync_fury2", ROOT / "README.md")}[backends.NAME]


def _check_the_example() -> subprocess.CompletedProcess:
    text = PAGE.read_text(encoding="utf-8")
    example = re.search(rf"Save as `{MODULE}.py`.*?```python\n(.*?)```", text, re.S).group(1)
    with tempfile.TemporaryDirectory() as where:
        (Path(where) / f"{MODULE}.py").write_text(example, encoding="utf-8")
        return subprocess.run(
            [sys.executable, "-m", "pytest", "--pyargs", "conformance", "-m", "sync", "-q", "-p", "no:cacheprovider",
             "--sync", f"{MODULE}:MySync"],
            cwd=where, capture_output=True, text=True, env=child_environment(),
            preexec_fn=dies_with_this_process(waited_for=True))


def background_runs(items) -> dict:
    """The example's run is as long as a right sync's: start it with the session (``background``)."""
    return {"readme-example": (1, _check_the_example)}


def test_readme_example_passes_every_sync_check():
    proc = background.result("readme-example", _check_the_example)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-2000:]
    assert " passed" in proc.stdout and "failed" not in proc.stdout.splitlines()[-1]
