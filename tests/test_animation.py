"""``render SCENE --gif OUT.gif --frames A:B:S``: an animation of the chosen frames, each checked as
``check`` checks it, failing frames with a red border and a caption naming their worst problem."""

from __future__ import annotations

import contextlib
import importlib.util
import io
import os
import re
import shlex
import textwrap
from pathlib import Path

import numpy as np
import pytest
from PIL import Image, ImageSequence

from conformance import cli, scenes
from conformance.rendering import animation
from conformance.rendering import outline
from conformance.sync.printed import reproduce_command


def _render(argv, cwd: Path) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    old = os.getcwd()
    os.chdir(cwd)  # a sync given as module:attribute is found in the directory the command runs from
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            status = cli.main(argv)
    finally:
        os.chdir(old)
    return status, out.getvalue(), err.getvalue()


def _frames(path: Path) -> list[np.ndarray]:
    with Image.open(path) as gif:
        return [np.asarray(frame.convert("RGB")) for frame in ImageSequence.Iterator(gif)]


def _red_border(picture: np.ndarray) -> bool:
    """Is the outer ring of the picture (as wide as a failing frame's border) all red?"""
    width = animation.border_width((picture.shape[1], picture.shape[0]))
    ring = np.concatenate([picture[:width].reshape(-1, 3), picture[-width:].reshape(-1, 3),
                           picture[:, :width].reshape(-1, 3), picture[:, -width:].reshape(-1, 3)]).astype(int)
    red = (ring[:, 0] > 200) & (ring[:, 1] < 60) & (ring[:, 2] < 60)
    return bool(red.mean() > 0.99)


def _no_red_edge(picture: np.ndarray) -> bool:
    edge = np.concatenate([picture[0], picture[-1], picture[:, 0], picture[:, -1]]).astype(int)
    return not ((edge[:, 0] > 200) & (edge[:, 1] < 60) & (edge[:, 2] < 60)).any()


def _failing_frames(out: str) -> list[int]:
    match = re.search(r"marked with a red border\): ([\d, ]+)", out)
    return [int(n) for n in match.group(1).split(", ")] if match else []


def test_gif_has_one_picture_per_chosen_frame_at_the_asked_size(tmp_path):
    status, out, err = _render(["render", "free_fall", "--gif", "ff.gif", "--frames", "0:20:5", "--size", "160", "120"],
                               tmp_path)
    assert status == 0, out + err
    pictures = _frames(tmp_path / "ff.gif")
    assert len(pictures) == 5 and {p.shape for p in pictures} == {(120, 160, 3)}
    assert all(_no_red_edge(p) for p in pictures), "a passing frame is marked"
    assert "wrote ff.gif (5 pictures, frames 0..20 every 5, 160x120, scene 'free_fall', sync 'reference')" in out
    assert "PASS free_fall" in out
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ff.gif"], "a temporary file was left behind"
    with Image.open(tmp_path / "ff.gif") as gif:
        assert gif.info.get("loop") == 0 and gif.info.get("duration") == animation.FRAME_SECONDS * 1000


def test_wrong_sync_gets_its_failing_frames_marked(tmp_path):
    """``wrong_syncs:TransposedRotation`` fails ``tumbling``: every pictured frame it fails has the red
    border, and the reference sync's pictures of the same frames have none."""
    argv = ["render", "tumbling", "--frames", "0:20:10", "--size", "200", "150"]
    status, out, err = _render([*argv, "--sync", "wrong_syncs:TransposedRotation", "--gif", "bad.gif"], tmp_path)
    assert status == 1, out + err
    failing = _failing_frames(out)
    assert failing, out
    bad = _frames(tmp_path / "bad.gif")
    assert [frame for frame, picture in zip(range(0, 21, 10), bad) if _red_border(picture)] == failing
    assert f"frame {failing[0]}: " in out and "worst: " in out
    # Where pyBullet has the misdrawn bodies is outlined on exactly the failing frames.
    assert [frame for frame, picture in zip(range(0, 21, 10), bad) if _outlined(picture)] == failing
    status, out, err = _render([*argv, "--gif", "good.gif"], tmp_path)
    assert status == 0, out + err
    good = _frames(tmp_path / "good.gif")
    assert len(good) == len(bad) == 3
    assert not any(_red_border(p) for p in good) and all(_no_red_edge(p) for p in good)
    assert not any(_outlined(p) for p in good)


def _outlined(picture: np.ndarray) -> bool:
    return bool((picture == outline.OUTLINE_COLOUR).all(axis=2).sum() > 20)


def test_the_outline_is_the_edge_of_the_regions_it_outlines():
    ids = np.full((20, 30), -1)
    ids[5:15, 5:15] = 0  # a 10 px square
    ids[5:15, 15:25] = 1  # touching another target
    ring = outline.edges(ids, [0])
    assert ring.sum() == 100 - 36 and not ring[ids != 0].any(), "two pixels wide, inside the square only"
    assert not outline.edges(ids, [2]).any(), "a target pyBullet does not show has no outline"
    ids[:, :] = 0  # a target covering the whole picture is outlined along the picture's border
    assert outline.edges(ids, [0]).sum() == 20 * 30 - 16 * 26


def test_the_outline_is_drawn_where_pybullet_has_the_body_and_a_right_drawing_fills_it():
    from conformance import backends, sync
    from conformance.sync import runner
    from conformance.rendering import silhouettes

    size = (200, 150)
    for spec, inside in (("reference", 0.99), ("wrong_syncs:OneStepLate", None)):
        with runner.running("free_fall", sync.load(spec)) as run:
            run.advance(100)
            ring = outline.expected_outline(run, ["body"], size)
            mask = silhouettes.pybullet_mask(run.scene, run.scene.bindings, run.scene.camera, size)
            assert ring.any() and not ring[mask != 0].any(), "outline pixels are pyBullet's pixels of the body"
            drawn = backends.render_ids(run.drawing, run.scene.camera, size) == 0
            covered = drawn[ring].mean()
            if inside is not None:  # the right drawing covers its outline (up to an edge pixel)
                assert covered >= inside, covered
            else:  # a step late (measured at frame 100: 84 % covered) leaves part of the outline bare
                assert covered < 0.9, covered


def test_frames_that_pass_and_frames_that_fail_in_one_animation(tmp_path):
    """A sync that stops syncing after frame 5: frames 0 and 3 pass, 6, 9 and 12 fail, and only those
    are marked."""
    (tmp_path / "stops_syncing_anim.py").write_text(textwrap.dedent("""
        from conformance.implementations.reference import ReferenceSync

        class StopsAfterFive(ReferenceSync):
            calls = 0

            def __call__(self):
                self.calls += 1
                if self.calls <= 6:  # frames 0 to 5
                    super().__call__()
    """))
    status, out, err = _render(["render", "free_fall", "--sync", "stops_syncing_anim:StopsAfterFive", "--gif", "s.gif",
                                "--frames", "0:12:3", "--size", "160", "120"], tmp_path)
    assert status == 1, out + err
    assert _failing_frames(out) == [6, 9, 12]
    marked = [_red_border(p) for p in _frames(tmp_path / "s.gif")]
    assert marked == [False, False, True, True, True]


def test_a_failure_s_reproduce_line_becomes_an_animation(tmp_path):
    spec = scenes.get("free_fall")
    line = reproduce_command("free_fall", "wrong_syncs:TransposedRotation", 4, dict(spec.defaults))
    words = shlex.split(line)
    assert words[:4] == ["python", "-m", "conformance", "check"]
    status, out, err = _render(["render", *words[4:], "--gif", "repro.gif", "--size", "96", "64"], tmp_path)
    assert status == 1, out + err
    assert len(_frames(tmp_path / "repro.gif")) == 5  # --frames 4 means frames 0 to 4, as in check


def test_marking_keeps_the_size_and_only_failing_frames_get_red():
    picture = np.full((60, 80, 3), 255, dtype=np.uint8)
    passing = animation.FrameCheck(frame=3, problems=(), worst_vertex="fine", worst_problem=None)
    failing = animation.FrameCheck(frame=4, problems=("x",), worst_vertex="x", worst_problem="a very long "
                                   "description of what went wrong " * 5)
    assert animation.mark(picture, passing).shape == animation.mark(picture, failing).shape == picture.shape
    assert not _red_border(animation.mark(picture, passing)) and _red_border(animation.mark(picture, failing))
    assert (picture == 255).all(), "the picture given was changed"


@pytest.mark.skipif(importlib.util.find_spec("imageio_ffmpeg") is not None, reason="imageio-ffmpeg is installed")
def test_mp4_without_imageio_ffmpeg_says_what_to_install(tmp_path):
    status, out, err = _render(["render", "free_fall", "--gif", "a.mp4", "--frames", "0:4"], tmp_path)
    assert status == 2
    assert "--gif='a.mp4': writing an MP4 needs the package imageio-ffmpeg" in err and "pip install imageio-ffmpeg" in err
    assert not list(tmp_path.iterdir())


@pytest.mark.skipif(importlib.util.find_spec("imageio_ffmpeg") is None, reason="needs imageio-ffmpeg")
def test_mp4_with_imageio_ffmpeg(tmp_path):
    import imageio.v3 as iio

    status, out, err = _render(["render", "free_fall", "--gif", "a.mp4", "--frames", "0:8:2", "--size", "96", "64"],
                               tmp_path)
    assert status == 0, out + err
    frames = iio.imread(tmp_path / "a.mp4", plugin="FFMPEG")
    assert frames.shape[0] == 5 and frames.shape[1:3] == (64, 96)


def test_nothing_is_written_when_rendering_fails(tmp_path, monkeypatch):
    def broken(*args, **kwargs):
        raise RuntimeError("encoder broke")

    monkeypatch.setattr(animation, "encode", broken)
    with pytest.raises(RuntimeError, match="encoder broke"):
        _render(["render", "free_fall", "--gif", "x.gif", "--frames", "0:2", "--size", "32", "32"], tmp_path)
    assert not list(tmp_path.iterdir())
