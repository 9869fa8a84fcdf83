"""Rendering, the virtual display, and the command line, as a user meets them."""

from __future__ import annotations

import os
import re
import textwrap
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from conformance import backends, cli
from conformance.rendering import images
from conformance.backends import display
from conformance.errors import DisplayUnavailable
from children import run as _run, said as _said


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


# -- a renderer that cannot start (conformance/backends/renderer_start.py) ---------------------------------------

#: Per backend: an environment its renderer cannot start in, and what the kit's paragraph must say.
BROKEN = {
    "vtk": ({"GALLIUM_DRIVER": "zink"},  # without LIBGL_ALWAYS_SOFTWARE=1 VTK aborts: exit status 134
            ["VTK cannot start its OpenGL renderer", "GALLIUM_DRIVER='zink'", "was killed by signal 6 (SIGABRT)",
             "unset GALLIUM_DRIVER", "set LIBGL_ALWAYS_SOFTWARE=1 GALLIUM_DRIVER=zink and XDG_RUNTIME_DIR"]),
    "pygfx": ({"WGPU_BACKEND_TYPE": "Metal"},  # a backend wgpu was not built with: no adapter
              ["FURY 2 renders through wgpu, which could not start", "WGPU_BACKEND_TYPE='Metal'",
               "No suitable graphics adapter found", "unset WGPU_BACKEND_TYPE", "mesa-vulkan-drivers"]),
}


def test_a_renderer_that_cannot_start_is_one_paragraph_on_the_command_line(tmp_path):
    variables, phrases = BROKEN[backends.NAME]
    done = _run(["-m", "conformance", "render", "free_fall", "--step", "10", "--out", str(tmp_path / "ff.png")],
                tmp_path, **variables)
    assert done.returncode == 2, _said(done)  # the kit's error status, not 134 (SIGABRT) or a negative one
    errors = [line for line in done.stderr.splitlines() if line.startswith("error: ")]
    assert len(errors) == 1 and all(phrase in errors[0] for phrase in phrases), _said(done)
    assert "Fatal Python error" not in done.stderr and "Traceback" not in done.stderr, _said(done)
    assert not (tmp_path / "ff.png").exists()


def test_a_renderer_that_cannot_start_fails_the_checks_with_the_paragraph_under_pytest(tmp_path):
    variables, phrases = BROKEN[backends.NAME]
    done = _run(["-m", "pytest", "--pyargs", "conformance", "-p", "no:cacheprovider", "-q", "-k",
                 "test_golden_render and free_fall", "--conformance-results", str(tmp_path / "results")],
                tmp_path, **variables)
    assert done.returncode == 1, _said(done)  # checks failed: not 134, not an internal error (3)
    kind = "DisplayUnavailable" if backends.NAME == "vtk" else "BackendError"
    paragraphs = [line for line in done.stdout.splitlines() if line.startswith(f"{kind}: ")]
    assert len(paragraphs) == 1 and all(phrase in paragraphs[0] for phrase in phrases), _said(done)
    assert "Fatal Python error" not in done.stderr and "1 failed" in done.stdout, _said(done)


vtk_only = pytest.mark.skipif(backends.NAME != "vtk", reason="FURY 2 renders without OpenGL or X")


@vtk_only
@pytest.mark.parametrize("variables", [
    {"LIBGL_ALWAYS_SOFTWARE": "1", "GALLIUM_DRIVER": "softpipe"},
    {"LIBGL_ALWAYS_SOFTWARE": "1", "GALLIUM_DRIVER": "zink", "XDG_RUNTIME_DIR": None},  # set to tmp_path below
], ids=["softpipe", "zink"])
def test_a_driver_that_can_start_still_renders(tmp_path, variables):
    variables = {k: v if v is not None else str(tmp_path) for k, v in variables.items()}
    out = tmp_path / "ff.png"
    done = _run(["-m", "conformance", "render", "free_fall", "--step", "10", "--size", "120", "90", "--out", str(out)],
                tmp_path, **variables)
    assert done.returncode == 0, _said(done)
    assert (np.asarray(Image.open(out)) != 255).any(), "the picture is blank: nothing was drawn"


# The tests below change driver variables in a child of their own, never in this process's environment:
# the kit's background runs (tests/background.py) start processes from it at any moment of the session.

def _child(tmp_path, code: str, **variables) -> str:
    """Run ``code`` in a fresh Python with ``variables``; what it printed (it must exit 0)."""
    done = _run(["-c", textwrap.dedent(code)], tmp_path, **variables)
    assert done.returncode == 0, _said(done)
    return done.stdout.strip().splitlines()[-1]


@vtk_only
def test_an_opengl_older_than_3_2_is_refused_too(tmp_path):
    """VTK neither aborts nor draws here: it logs an error and goes on."""
    said = _child(tmp_path, """
        from conformance.backends import display, renderer_start
        from conformance.errors import DisplayUnavailable
        display.ensure_display()
        try:
            renderer_start.check_gl()
        except DisplayUnavailable as refused:
            print("refused:", str(refused).replace("\\n", "<newline>"))
    """, MESA_GL_VERSION_OVERRIDE="3.0")
    assert re.match(r"refused: .*MESA_GL_VERSION_OVERRIDE='3\.0'.*exited with status 1, saying: .*VTK found no OpenGL "
                    r"3\.2 or later.* To fix it, unset MESA_GL_VERSION_OVERRIDE", said), said
    assert "<newline>" not in said


def test_the_probe_runs_once_per_process_and_environment(tmp_path):
    assert _child(tmp_path, """
        import os
        from conformance.backends import renderer_start
        from conformance.errors import DisplayUnavailable

        answers, probes = iter([None, "the paragraph"]), []
        renderer_start._probe = lambda: probes.append(1) or next(answers)
        renderer_start.check_gl()
        renderer_start.check_gl()
        assert len(probes) == 1, probes
        os.environ["GALLIUM_DRIVER"] = "zink"  # another environment: asked again, and the error kept
        for _ in range(2):
            try:
                renderer_start.check_gl()
                raise SystemExit("check_gl passed, but should raise the paragraph")
            except DisplayUnavailable as refused:
                assert str(refused) == "the paragraph", refused
        assert len(probes) == 2, probes
        del os.environ["GALLIUM_DRIVER"]
        renderer_start._answers.clear()  # as in a child process, which inherits the parent's pass
        renderer_start.check_gl()
        assert len(probes) == 2, probes
        print("ok")
    """) == "ok"


def test_what_the_child_said_is_one_line_without_vtks_log_prefix():
    from conformance.backends.renderer_start import last_words

    stderr = ("pybullet build time: Jan 29 2025 23:17:20\nlibGL error: failed to load driver: swrast\n"
              "\x1b[0m\x1b[31m2026-11-25 15:20:18.086 (   0.183s) [    7FD697A1DB80]vtkXOpenGLRenderWindow.:651    ERR| "
              "vtkXOpenGLRenderWindow (0x55c24ce9f2f0): Cannot create GLX context.  Aborting.\x1b[0m\n")
    assert last_words(stderr) == "libGL error: failed to load driver: swrast; Cannot create GLX context. Aborting."
    assert last_words("") == "(nothing)"


@vtk_only
def test_an_app_whose_driver_cannot_start_gets_the_paragraph(tmp_path):
    """App mode: the app's own process probes before the app makes its window, which would abort it."""
    message = _child(tmp_path, f"""
        from conformance.apps import launch
        try:
            launch.record({str(Path(__file__).parent / "apps" / "box_vtk.py")!r}, ticks=2)
        except launch.AppFailed as failed:
            print(str(failed).replace("\\n", "<newline>"))
    """, GALLIUM_DRIVER="zink")
    assert "box_vtk.py: VTK cannot start its OpenGL renderer" in message and "GALLIUM_DRIVER='zink'" in message
    assert "unset GALLIUM_DRIVER" in message and "<newline>" not in message
