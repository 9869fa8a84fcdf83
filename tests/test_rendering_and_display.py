"""Rendering, the virtual display, and the command line, as a user meets them."""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from conformance import cli, display, images
from conformance.errors import DisplayUnavailable


def test_identical_check_fails_on_one_changed_pixel():
    a = np.zeros((4, 5, 3), dtype=np.uint8)
    b = a.copy()
    b[2, 3, 1] = 7
    with pytest.raises(AssertionError, match="1 of 20 pixels differ .largest channel difference 7"):
        images.assert_identical(a, b, what="x")
    with pytest.raises(AssertionError, match="sizes differ"):
        images.assert_identical(a, a[:3], what="x")
    images.assert_identical(a, a.copy(), what="x")


def test_missing_xvfb_says_what_to_install(monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.setattr(display, "_started", None)
    monkeypatch.setattr(display.shutil, "which", lambda name: None)
    with pytest.raises(DisplayUnavailable, match=r"Xvfb is not on PATH; install it with `sudo apt-get install xvfb`"):
        display.ensure_display()


def test_virtual_display_is_started_and_stopped(monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.setattr(display, "_started", None)
    with display.virtual_display():
        import os

        assert os.environ.get("DISPLAY", "").startswith(":")
        assert display._started is not None
    assert display._started is None and "DISPLAY" not in __import__("os").environ


class _RefusingXlib:
    """libX11 whose ``XOpenDisplay`` refuses the first ``refusals`` connections."""

    def __init__(self, refusals):
        self.refusals, self.opened, self.closed = refusals, 0, []

    def XOpenDisplay(self, name):
        self.opened += 1
        return 0 if self.opened <= self.refusals else 0xD15

    def XCloseDisplay(self, pointer):
        self.closed.append(pointer)


def test_x_connection_is_retried_until_the_server_answers(monkeypatch):
    monkeypatch.setenv("DISPLAY", ":99")
    xlib = _RefusingXlib(refusals=3)
    monkeypatch.setattr(display, "_xlib", lambda: xlib)
    monkeypatch.setattr(display, "CONNECT_PAUSE", 0.001)
    assert display.x_connection() == 0xD15 and xlib.opened == 4
    display.close_x_connection(0xD15)
    assert xlib.closed == [0xD15]


def test_x_connection_refused_every_time_is_a_clear_error_not_a_crash(monkeypatch):
    monkeypatch.setenv("DISPLAY", ":99")
    xlib = _RefusingXlib(refusals=100)
    monkeypatch.setattr(display, "_xlib", lambda: xlib)
    monkeypatch.setattr(display, "CONNECT_PAUSE", 0.001)
    with pytest.raises(DisplayUnavailable, match=r"Could not connect to the X display ':99' \(8 attempts"):
        display.x_connection()
    assert xlib.opened == display.CONNECT_ATTEMPTS


def test_x_connection_to_a_display_nobody_serves_fails_cleanly(monkeypatch):
    monkeypatch.setenv("DISPLAY", ":4711")
    monkeypatch.setattr(display, "CONNECT_ATTEMPTS", 2)
    with pytest.raises(DisplayUnavailable, match="unset DISPLAY to let the kit start its own Xvfb"):
        display.x_connection()


def test_render_command_writes_the_png(tmp_path, capsys):
    out = tmp_path / "sub" / "ff.png"
    assert cli.main(["render", "free_fall", "--step", "10", "--size", "120", "90", "--out", str(out)]) == 0
    picture = np.asarray(Image.open(out))
    assert picture.shape == (90, 120, 3)
    assert (picture != 255).any(), "the picture is blank: nothing was drawn"
    assert not list(out.parent.glob("*.tmp")), "a temporary file was left behind"
    assert "wrote" in capsys.readouterr().out


def test_check_command_exit_codes(capsys):
    assert cli.main(["check", "free_fall", "--sync", "reference", "--frames", "5"]) == 0
    assert cli.main(["check", "free_fall", "--sync", "wrong_syncs:TransposedRotation", "--frames", "5"]) == 1
    out = capsys.readouterr().out
    assert "PASS free_fall" in out and "FAIL free_fall with sync 'wrong_syncs:TransposedRotation': first failure at frame 0" in out


def test_command_line_errors_are_one_line(capsys):
    assert cli.main(["render", "no_such_scene"]) == 2
    assert cli.main(["check", "free_fall", "--params", "[1, 2]"]) == 2
    assert cli.main(["check", "free_fall", "--sync", "nowhere_xyz:S"]) == 2
    err = capsys.readouterr().err
    assert "scene='no_such_scene', but should be one of:" in err
    assert "is a JSON list, but should be an object" in err
    assert "importing module 'nowhere_xyz' failed" in err


def test_scenes_command_lists_every_scene(capsys):
    from conformance import scenes

    assert cli.main(["scenes", "-v"]) == 0
    out = capsys.readouterr().out
    for name in scenes.names():
        assert name in out


def test_xvfb_that_fails_to_start_is_a_clear_error(monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.setattr(display, "_started", None)
    monkeypatch.setattr(display, "SCREEN", "not-a-screen")  # Xvfb refuses it and exits
    with pytest.raises(DisplayUnavailable, match=r"Xvfb is installed but did not start \(exit status \d+; it said: .+\)"):
        display.ensure_display()
    assert "DISPLAY" not in __import__("os").environ and display._started is None
