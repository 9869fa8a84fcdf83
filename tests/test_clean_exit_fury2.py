"""FURY 2 renders without X: a run that renders starts no Xvfb and sets no ``DISPLAY``, and killing it
leaves nothing behind. (On FURY 0.12, ``tests/test_clean_exit.py`` kills runs that own an Xvfb.)"""

from __future__ import annotations

import os
import signal
import subprocess
import sys

import pytest

from conformance import backends

pytestmark = pytest.mark.skipif(backends.NAME != "pygfx" or not sys.platform.startswith("linux"),
                                reason="FURY 2's off-screen rendering on Linux (FURY 0.12's is in test_clean_exit.py)")

RENDER_AND_WAIT = """
import os, time
import numpy as np
from conformance import backends, sync
from conformance.sync import runner
from conformance.backends import display
with runner.running("free_fall", sync.load("reference")) as run:
    picture = backends.render(run.drawing, run.scene.camera, (64, 48))
    print("rendered", int((picture != 255).any()), display.server_pid(), os.environ.get("DISPLAY", "-"), flush=True)
    time.sleep(300)
"""


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGKILL], ids=["SIGTERM", "SIGKILL"])
def test_fury2_renders_without_a_display_and_leaves_nothing(tmp_path, signum):
    import test_clean_exit as x  # its /proc helpers: the module's tests skip here, its functions do not

    env = {k: v for k, v in os.environ.items() if k != "DISPLAY"}
    process = subprocess.Popen([sys.executable, "-c", RENDER_AND_WAIT], cwd=tmp_path, env=env, text=True,
                               stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    said = []
    while not (line := process.stdout.readline()).startswith("rendered ") and line:
        said.append(line)
    assert line, f"the process ended (status {process.wait()}) before rendering:\n{''.join(said)[-3000:]}"
    assert line.split()[1:] == ["1", "None", "-"], line  # something drawn; no Xvfb; no DISPLAY
    children = x._descendants(process.pid)
    assert not [pid for pid in children if (stat := x._stat(pid)) and stat[0] == "Xvfb"]
    assert x._kill(process, signum) == -signum
    x._assert_gone(children, "a child of the rendering process")
