"""A screenshot of an HTML page with headless Chromium (to look at reports, and regenerate docs/ pictures).

Chromium is not a dependency of the kit: on Debian, ``apt-get install chromium``. It runs with a
throw-away profile, no network services of its own (no sync, updates or background fetches) and no
sandbox (which needs privileges a container or CI runner may not grant).
"""

from __future__ import annotations

import os
import shutil
import subprocess
import tempfile
from pathlib import Path

from conformance.errors import ConformanceError

__all__ = ["ChromiumMissing", "ScreenshotFailed", "find_chromium", "screenshot"]

#: Executable names tried in order (Debian's package is ``chromium``).
CANDIDATES = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable")

_FLAGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
          "--disable-background-networking", "--disable-component-update", "--disable-sync",
          "--hide-scrollbars")


class ChromiumMissing(ConformanceError):
    """No Chromium (or Chrome) executable was found on ``PATH``."""


class ScreenshotFailed(ConformanceError):
    """Chromium ran but did not write the screenshot."""


def find_chromium() -> str:
    """The path of a Chromium executable; ``$CHROMIUM`` wins if set."""
    explicit = os.environ.get("CHROMIUM")
    for name in ((explicit,) if explicit else CANDIDATES):
        path = shutil.which(name)
        if path:
            return path
    tried = explicit if explicit else ", ".join(CANDIDATES)
    raise ChromiumMissing(f"no Chromium executable found (tried {tried} on PATH); install it "
                          "(Debian: apt-get install -y chromium) or set $CHROMIUM to its path")


def screenshot(html_path: str | os.PathLike, png_path: str | os.PathLike,
               size: tuple[int, int] = (1280, 1600), *, timeout: float = 120.0) -> Path:
    """Render ``html_path`` in a ``size`` (width, height) window and write a PNG to ``png_path``.

    The PNG appears complete or not at all (written beside it under a temporary name, then renamed).
    Raises :class:`ChromiumMissing` when there is no Chromium, :class:`ScreenshotFailed` when it
    exits without writing the picture (its output is in the message).
    """
    chromium = find_chromium()
    html_path, png_path = Path(html_path).resolve(), Path(png_path).resolve()
    if not html_path.is_file():
        raise FileNotFoundError(f"no page to screenshot at {html_path}")
    png_path.parent.mkdir(parents=True, exist_ok=True)
    width, height = (int(v) for v in size)
    fd, tmp = tempfile.mkstemp(prefix=f".{png_path.name}.", suffix=".png", dir=png_path.parent)
    os.close(fd)
    os.unlink(tmp)  # Chromium writes the file itself; an existing one would hide a failed run
    try:
        with tempfile.TemporaryDirectory(prefix="chromium-profile-") as profile:
            command = [chromium, *_FLAGS, f"--user-data-dir={profile}", f"--screenshot={tmp}",
                       f"--window-size={width},{height}", html_path.as_uri()]
            try:
                result = subprocess.run(command, capture_output=True, text=True, timeout=timeout)
            except subprocess.TimeoutExpired:
                raise ScreenshotFailed(f"Chromium took more than {timeout:g} s to screenshot {html_path}") from None
        if not os.path.isfile(tmp) or os.path.getsize(tmp) == 0:
            output = (result.stderr or result.stdout).strip()[-2000:]
            raise ScreenshotFailed(f"Chromium (exit status {result.returncode}) wrote no screenshot of "
                                   f"{html_path}; its output:\n{output}")
        os.replace(tmp, png_path)
    finally:
        Path(tmp).unlink(missing_ok=True)
    return png_path
