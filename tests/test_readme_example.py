"""The README's complete example is a right sync implementation: copied out verbatim, it passes."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

README = Path(__file__).resolve().parent.parent / "README.md"


def test_readme_example_passes_every_sync_check(tmp_path):
    text = README.read_text(encoding="utf-8")
    example = re.search(r"Save as `my_sync.py`.*?```python\n(.*?)```", text, re.S).group(1)
    (tmp_path / "my_sync.py").write_text(example, encoding="utf-8")
    proc = subprocess.run(
        [sys.executable, "-m", "pytest", "--pyargs", "conformance", "-m", "sync", "-q", "-p", "no:cacheprovider",
         "--sync", "my_sync:MySync"],
        cwd=tmp_path, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-2000:]
    assert " passed" in proc.stdout and "failed" not in proc.stdout.splitlines()[-1]
