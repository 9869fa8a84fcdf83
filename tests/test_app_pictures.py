"""The ``pictured`` check (conformance.apps.pictured) on pictures made by hand: a body shown where
pyBullet's renderer shows it passes; one hidden, faint, or drawn from stale GPU data fails with the
tick, the body, the pixels off against the allowance, and its diagnosis; static bodies are background
and frames the kit does not judge are left out. The pictures a real app gets are the examples' (tests/test_examples.py)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from app_recordings import CORNERS, HALF, box_frame, draw, motion, recording, track
from conformance import apps, backends
from conformance.apps import judge, recording as recording_mod
from conformance.apps.bodies import Frame

SIZE = (64, 48)


def _square(top=10, left=10, side=20) -> np.ndarray:
    mask = np.zeros(SIZE[::-1], dtype=bool)
    mask[top:top + side, left:left + side] = True
    return mask


def _shot(fury: np.ndarray, bullet: np.ndarray, *, vertices: int = 8, faint=None, stale=None, hidden=(False,),
          touching=()) -> dict:
    """A picture at the last tick: ``fury`` and ``bullet`` are label pictures (the app-wide vertex seen,
    and the frame pyBullet shows; -1 none)."""
    return {"tick": 40, "size": list(SIZE), "camera": {}, "vertices": fury.astype(np.int32),
            "bullet": bullet.astype(np.int32),
            "faint": np.zeros(vertices, bool) if faint is None else faint,
            "stale": np.zeros(vertices, bool) if stale is None else stale,
            "hidden": list(hidden), "touching": [list(p) for p in touching], "notes": []}


def _judged(shots, frames=None, poses=None, tracks=None):
    pos, orn = motion()
    r = recording(frames or [box_frame()], poses or [(pos, orn)], tracks or [track(draw(pos, orn))])
    r.pictures = list(shots)
    return judge(r)["pictured"]


def _labels(mask, value) -> np.ndarray:
    return np.where(mask, value, -1)


def test_a_body_where_pyBullet_draws_it_passes_even_an_edge_pixel_off():
    verdict = _judged([_shot(_labels(_square(), 0), _labels(_square(left=11), 0))])
    assert verdict.passed, verdict.message()
    assert verdict.worst == 0.0
    record, images = verdict.pictures[0]
    assert record.passed and images == {}  # pictures are kept for failures


def test_a_body_missing_from_the_picture_fails_naming_tick_body_and_pixels():
    verdict = _judged([_shot(np.full(SIZE[::-1], -1), _labels(_square(), 0))])
    assert not verdict.passed
    line = verdict.lines[0]
    assert "hand-made.py, tick 40: body 0 base (box0)" in line
    assert "400 pixels off beyond the 1 px edge slack, 8 allowed" in line  # (1 - 0.98) × 400
    assert verdict.diagnoses == []  # nothing recorded says why: no diagnosis
    record, images = verdict.pictures[0]
    assert not record.passed and set(images) == {"fury_mask", "pybullet_mask", "mask_difference"}
    assert record.scene == "app-hand-made" and record.frame == 40


def test_a_body_drawn_two_pixels_off_fails():
    verdict = _judged([_shot(_labels(_square(left=12), 0), _labels(_square(), 0))])
    assert not verdict.passed, "a 2 px shift is beyond the 1 px slack, as for the scene checks"


def test_a_sliver_is_left_out_and_a_body_seen_whole_is_not():
    """A body showing only an edge in both pictures (a disc's rim behind another) is left out with a note:
    which renderer covers those pixels is its tessellation's business (:func:`pictured.edges_only`)."""
    from conformance.apps import pictured

    fury, bullet = np.zeros(SIZE[::-1], bool), np.zeros(SIZE[::-1], bool)
    fury[10, 2:62], bullet[14, 2:62] = True, True  # 60 pixels each, 4 px apart: IoU 0 as judged
    verdict = _judged([_shot(_labels(fury, 0), _labels(bullet, 0))])
    assert verdict.passed and "showed only an edge" in " ".join(verdict.notes), verdict.message()
    assert pictured.edges_only(_labels(fury, 0), _labels(bullet, 0)).sum() == 120
    whole = _square(top=12, side=10) | bullet  # drawn whole in one picture: judged, and off
    assert not _judged([_shot(_labels(fury, 0), _labels(whole, 0))]).passed


def test_only_the_first_failing_picture_is_told_body_by_body():
    missing = _shot(np.full(SIZE[::-1], -1), _labels(_square(), 0))
    verdict = _judged([missing, {**missing, "tick": 80}])
    assert len(verdict.lines) == 2 and "tick 40: body 0 base" in verdict.lines[0], verdict.lines
    assert verdict.lines[1].startswith("hand-made.py, tick 80: as well, 1 body not where pyBullet's renderer draws it")


def test_a_faint_or_hidden_actor_is_diagnosed_hidden():
    faint = _judged([_shot(_labels(_square(), 0), _labels(_square(), 0), faint=np.ones(8, bool))])
    assert not faint.passed and faint.diagnoses == ["hidden"]
    hidden = _judged([_shot(np.full(SIZE[::-1], -1), _labels(_square(), 0), hidden=(True,))])
    assert not hidden.passed and hidden.diagnoses == ["hidden"]


def test_vertices_the_gpu_holds_elsewhere_are_diagnosed_stale_gpu():
    stale = np.zeros(8, bool)
    stale[:4] = True
    verdict = _judged([_shot(_labels(_square(left=30), 0), _labels(_square(), 0), stale=stale)])
    assert not verdict.passed and verdict.diagnoses == ["stale-gpu"]


def test_a_static_body_is_background_in_both_pictures():
    """A ground plate drawn by the app (or not) is never judged: mass 0, the world's."""
    pos, orn = motion()
    plate = dataclasses.replace(box_frame(1), mass=0.0)
    still = (np.zeros_like(pos), np.tile([0.0, 0.0, 0.0, 1.0], (len(pos), 1)))
    tracks = [track(draw(pos, orn)), track(draw(*still), label="plate_actor")]
    fury = _labels(_square(), 0)
    fury[40:, :] = 8  # the plate's first vertex, drawn where pyBullet draws nothing
    verdict = _judged([_shot(fury, _labels(_square(), 0), vertices=16, hidden=(False, False))],
                      frames=[box_frame(), plate], poses=[(pos, orn), still], tracks=tracks)
    assert verdict.passed, verdict.message()


def test_pixels_of_a_frame_the_kit_does_not_judge_are_left_out():
    """A capsule (no box, sphere or cylinder: placed does not judge it) covers part of the box in
    pyBullet's picture: what it hides cannot be told, so those pixels count for neither."""
    pos, orn = motion()
    capsule = Frame(0, 1, -1, "capsule1", 1.0, (("capsule", (0.2, 0.05), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)),))
    bullet = _labels(_square(), 0)
    bullet[10:20, 10:30] = 1  # pyBullet shows the capsule in front of half the box
    verdict = _judged([_shot(_labels(_square(), 0), bullet)], frames=[box_frame(), capsule],
                      poses=[(pos, orn), (pos + 5, orn)])
    assert verdict.passed, verdict.message()


def test_a_body_drawn_only_as_another_shape_is_held_to_pyBullets_picture():
    """Every drawing of the box is flattened to half its height (FURY 0.12's own chain demo draws its 1 m discs
    as thin rods): placed cannot judge it, but the picture must still show what pyBullet simulates."""
    pos, orn = motion()
    flat = [track(draw(pos, orn, CORNERS * np.array([1.0, 1.0, 0.5])))]
    verdict = _judged([_shot(_labels(_square(top=15, left=15, side=10), 0), _labels(_square(), 0))], tracks=flat)
    assert not verdict.passed and verdict.diagnoses == ["not-its-shape"], verdict.message()
    drawn_right = _judged([_shot(_labels(_square(), 0), _labels(_square(), 0))], tracks=flat)
    assert drawn_right.passed, drawn_right.message()


def test_a_body_drawn_at_another_size_is_named_by_placed_not_by_its_picture():
    """The box drawn at half its size, every axis alike (a globalScaling applied twice): placed names it
    ``scaled`` with the factor, and the picture, which that explains, names no other shape (issue 48)."""
    pos, orn = motion()
    small = [track(draw(pos, orn, CORNERS / 2))]
    r = recording([box_frame()], [(pos, orn)], small)
    r.pictures = [_shot(_labels(_square(top=15, left=15, side=10), 0), _labels(_square(), 0))]
    verdicts = judge(r)
    assert verdicts["placed"].diagnoses == ["scaled"] and "0.5 times" in verdicts["placed"].message()
    assert not verdicts["pictured"].passed and verdicts["pictured"].diagnoses == [], verdicts["pictured"].message()


def test_a_decoration_beside_a_drawing_of_the_shape_leaves_the_body_out_of_the_picture():
    pos, orn = motion()
    tracks = [track(draw(pos, orn)), track(draw(pos, orn, CORNERS / 2), label="marker_actor")]
    fury = _labels(_square(), 0)
    fury[5:10, 5:10] = 8  # the marker's first vertex, where pyBullet shows nothing
    verdict = _judged([_shot(fury, _labels(_square(), 0), vertices=16, hidden=(False, False))], tracks=tracks)
    assert verdict.passed, verdict.message()


def test_a_decoration_pyBullet_does_not_have_hides_nothing_that_counts():
    """FURY's own demos add ``actor.axes()`` at the origin: held by the world, drawn in front of a body
    pyBullet shows whole. What it hides cannot be told, so its pixels are left out."""
    pos, orn = motion()
    still = (np.zeros_like(pos), np.tile([0.0, 0.0, 0.0, 1.0], (len(pos), 1)))
    tracks = [track(draw(pos, orn)), track(draw(*still), label="axes_actor")]
    fury = _labels(_square(), 0)
    fury[10:20, 10:20] = 8  # the axes' first vertex, in front of a quarter of the box
    verdict = _judged([_shot(fury, _labels(_square(), 0), vertices=16, hidden=(False, False))], tracks=tracks)
    assert verdict.passed, verdict.message()
    missing = _labels(_square(), 0)
    missing[10:20, 10:20] = -1  # nothing drawn there: the box is missing a quarter
    assert not _judged([_shot(missing, _labels(_square(), 0), vertices=16, hidden=(False, False))], tracks=tracks).passed


def test_pairs_in_contact_may_be_in_front_of_each_other_in_either_picture():
    pos, orn = motion()
    other = box_frame(1)
    tracks = [track(draw(pos, orn)), track(draw(pos + [0.2, 0, 0], orn), label="other_actor")]
    fury = np.where(_square(), 0, -1)
    fury[10:30, 25:45] = 8  # the other box's first vertex, in front of the first box's right quarter
    bullet = np.where(_square(), 0, -1)
    bullet[10:30, 30:45] = 1
    bullet[10:30, 25:30] = 0  # pyBullet puts the first box in front where they meet
    args = dict(frames=[box_frame(), other], poses=[(pos, orn), (pos + [0.2, 0, 0], orn)], tracks=tracks)
    apart = _judged([_shot(fury, bullet, vertices=16, hidden=(False, False))], **args)
    assert not apart.passed
    touching = _judged([_shot(fury, bullet, vertices=16, hidden=(False, False), touching=[(0, 1)])], **args)
    assert touching.passed, touching.message()


def test_a_run_without_a_picture_passes_and_says_why(tmp_path):
    verdict = _judged([{"tick": 40, "skipped": "the app's camera is a parallel projection"}])
    assert verdict.passed and "no picture at tick 40: the app's camera is a parallel projection" in verdict.notes


def test_pictures_survive_saving_and_loading(tmp_path):
    pos, orn = motion()
    r = recording([box_frame()], [(pos, orn)], [track(draw(pos, orn))])
    r.pictures = [_shot(_labels(_square(), 0), _labels(_square(), 0)), {"tick": 3, "skipped": "why"}]
    recording_mod.save(r, tmp_path / "r.npz")
    back = recording_mod.load(tmp_path / "r.npz")
    assert back.pictures[1] == {"tick": 3, "skipped": "why"}
    for key in ("vertices", "bullet", "faint", "stale"):
        np.testing.assert_array_equal(back.pictures[0][key], r.pictures[0][key])
    assert back.pictures[0]["tick"] == 40 and back.pictures[0]["hidden"] == [False]
    assert CORNERS.shape == (8, 3)


def _ball_frame(body: int = 1) -> Frame:
    return Frame(0, body, -1, f"ball{body}", 1.0, (("sphere", (0.2,), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)),))


def _behind_a_ball(shift: int, ball_shape: str = "sphere"):
    """A box whose lower part a ball hides, but for a 1 px strip along the box's bottom edge in
    pyBullet's picture; FURY's ball outline ``shift`` pixels wider all round (a coarser tessellation)."""
    pos, orn = motion()
    frames = [box_frame(), _ball_frame() if ball_shape == "sphere" else box_frame(1)]
    ball = CORNERS if ball_shape != "sphere" else np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * 0.2
    tracks = [track(draw(pos, orn)), track(draw(pos + 5, orn, ball), label="ball_actor")]
    size = (80, 48)
    box = np.zeros(size[::-1], dtype=bool)
    box[10:41, 10:61] = True
    bullet = np.where(box, 0, -1)
    bullet[15:40, 30:61] = 1
    fury = np.where(box, 0, -1)
    fury[15 - shift:40 + shift, 30 - shift:61 + shift] = 8
    shot = _shot(fury, bullet, vertices=16, hidden=(False, False))
    shot["size"] = list(size)
    return _judged([shot], frames=frames, poses=[(pos, orn), (pos + 5, orn)], tracks=tracks)


def test_a_ball_outline_a_pixel_wider_is_the_tessellation_slack_but_four_are_not():
    """pyBullet tessellates spheres and cylinders coarser than FURY: where one hides a body, the two
    outlines may differ by the edge slack without counting against the body behind it (here a strip of
    the box 1 px wide, which FURY's wider outline covers and no FURY pixel of the box is next to)."""
    assert _behind_a_ball(1).passed  # (2 px all round fails the ball's own silhouette: the slack is for what it hides)
    assert not _behind_a_ball(1, ball_shape="box").passed  # boxes are drawn alike: no such slack
    assert not _behind_a_ball(4).passed


#: Per FURY, an example app whose every recorded vertex is right and whose picture is not.
PICTURE_ONLY = {"vtk": "brick_wall_fades_in.py", "pygfx": "brick_wall_fades_in.py"}


#: Per FURY, the line that hides the small box app's actor from its 20th tick to its 40th, then shows it.
HIDE_FOR_A_WHILE = {"vtk": "    ball_actor.SetVisibility(not 20 <= cnt < 40)\n", "pygfx": "    box.visible = not 20 <= cnt < 40\n"}


def test_an_actor_hidden_for_a_while_is_seen_in_a_picture_during_the_run(tmp_path):
    """The pictures are taken at several ticks of a run (:func:`conformance.apps.picture.picture_ticks`),
    not only at its end: the box app ends at its 51st tick, shown, and was hidden at the kit's tick 30."""
    from conformance.apps import picture

    app = Path(__file__).parent / "apps" / f"box_{backends.NAME}.py"
    step = "    p.stepSimulation()\n"
    script = tmp_path / "app.py"
    script.write_text(app.read_text(encoding="utf-8").replace(step, step + HIDE_FOR_A_WHILE[backends.NAME]), encoding="utf-8")
    result = apps.check_app(script, ticks=120)
    assert [shot["tick"] for shot in result.recording.pictures] == [30, 51]
    failing = {c for c, v in result.verdicts.items() if not v.passed}
    assert failing == {"pictured"}, {c: result.verdicts[c].message()[:500] for c in failing}
    verdict = result.verdicts["pictured"]
    assert verdict.diagnoses == ["hidden"] and "tick 30: body 0 base" in verdict.lines[0], verdict.message()
    assert picture.picture_ticks(120, pictures=1) == [120]  # with one picture, at the end, it would pass


#: Per FURY, the line that hides the two-client app's second box (pyBullet client 1) from its 20th tick on.
HIDE_SECOND = {"vtk": "    pairs[1][2].SetVisibility(cnt < 20)\n", "pygfx": "    pairs[1][2].visible = cnt < 20\n"}


@pytest.mark.full("whole app runs in processes of their own; CI judges app mode end to end on every example app (test_examples)")
def test_bodies_of_every_client_are_in_pyBullets_picture(tmp_path):
    """Each pyBullet client is a world of its own, which an app may draw in one scene: pyBullet's picture
    is every client's, put together by its depth buffer. (With the first client's only, this right app's
    second box was "not where pyBullet draws it".)"""
    app = Path(__file__).parent / "apps" / f"two_clients_{backends.NAME}.py"
    result = apps.check_app(app, ticks=60)
    assert result.passed, {c: v.message()[:500] for c, v in result.verdicts.items() if not v.passed}
    judged = [{t["target"] for t in record.details["targets"]} for record, _ in result.verdicts["pictured"].pictures]
    assert all(targets == {"body 0 base (link0)", "client 1 body 0 base (link0)"} for targets in judged), judged
    script = tmp_path / "app.py"
    step = "    showm.render()\n"
    script.write_text(app.read_text(encoding="utf-8").replace(step, HIDE_SECOND[backends.NAME] + step), encoding="utf-8")
    hidden = apps.check_app(script, ticks=60).verdicts["pictured"]
    assert not hidden.passed and "client 1 body 0 base" in hidden.lines[0] and hidden.diagnoses == ["hidden"], hidden.message()


@pytest.mark.parametrize("ticks", [90])
def test_only_the_picture_check_sees_the_example_mistake(ticks, tmp_path):
    """On the installed FURY, a real app (the example) fails ``pictured`` with its diagnosis and passes
    every other check: a mistake no other app check catches; its pictures are written as the scene
    checks' are."""
    from conformance.apps import picture, pictured

    script = Path(__file__).resolve().parent.parent / "examples" / backends.NAME / "wrong" / PICTURE_ONLY[backends.NAME]
    result = apps.check_app(script, ticks=ticks)
    failing = {c for c, v in result.verdicts.items() if not v.passed}
    assert failing == {"pictured"}, {c: result.verdicts[c].message()[:500] for c in failing}
    verdict = result.verdicts["pictured"]
    assert verdict.diagnoses and set(verdict.diagnoses) == {"hidden"}
    assert f"tick {picture.picture_ticks(ticks)[0]}: body " in verdict.lines[0]
    written = pictured.keep(verdict, tmp_path, result.reproduce())
    assert {Path(w).name.rsplit("-", 1)[-1] for w in written} == {"fury_mask.png", "pybullet_mask.png", "mask_difference.png"}
    assert all((tmp_path / w).stat().st_size for w in written)


def test_a_face_stands_for_the_frame_that_alone_holds_one_of_its_corners():
    """A face whose first corner two frames hold equally (a chain disc's cap centre lies on the spherical
    joint, fixed in both links) is its next corner's frame's: labelled by its first corner, FURY 0.12's
    chain example had a disc's whole cap shown as its neighbour, in front of two discs (IoU 0.367)."""
    from conformance.apps import pictured
    from conformance.apps.attachment import Attachment

    pos, orn = motion()
    r = recording([box_frame(), box_frame(1)], [(pos, orn), (pos + [0.5, 0, 0], orn)], [track(draw(pos, orn))])
    # vertex 0: on the joint, tied, given to frame 0; vertices 1-3: frame 1's alone
    held = Attachment(frame=np.array([0, 1, 1, 1]), error=np.zeros((4, 1)), allowance=np.ones(4),
                      reference=np.zeros((4, 3)), tied=np.array([True, False, False, False]))
    faces = np.where(_square(), 0, -1)  # face 0 of the actor (corners 0, 1, 2) fills the square
    shot = {"faces": faces.astype(np.int32), "corners": np.array([[0, 1, 2]]), "bullet": faces.astype(np.int32),
            "faint": np.zeros(4, bool)}
    fury, bullet = pictured.labels(shot, r, [held], judged={0, 1}, background=set())
    assert set(np.unique(fury[_square()])) == {1}, "the face should be frame 1's, whose corners 1 and 2 only it holds"
    shot["bullet"] = np.where(_square(), 1, -1).astype(np.int32)
    fury, bullet = pictured.labels(shot, r, [held], judged={0, 1}, background=set())
    assert np.array_equal(fury, bullet)
    # with every corner tied, the first stands for the face, as before
    held.tied[:] = True
    fury, _ = pictured.labels(shot, r, [held], judged={0, 1}, background=set())
    assert set(np.unique(fury[_square()])) == {0}


@pytest.mark.parametrize("fury_depth, left_out", [(2.05, True), (1.95, False)])
def test_a_static_body_pyBullet_shows_in_front_hides_what_it_hides(fury_depth, left_out):
    """Issue 47: an app that does not draw its ground shows a body's part pyBullet's ground hides (a domino
    resting in it, a gripper turned into the floor): where pyBullet's static body is nearer than FURY's surface
    the pixels are left out; where FURY's surface is nearer (a body drawn where pyBullet has only ground) they
    are compared, and the body drawn there fails."""
    from conformance.apps import pictured

    fury = np.where(_square(), 0, -1)
    bullet = np.where(_square(top=14), 0, np.where(_square(), 1, -1))  # the body's lower band: the ground, in front
    shot = {"fury_depth": np.where(_square(), fury_depth, np.inf), "bullet_depth": np.where(bullet >= 0, 2.0, np.inf),
            "bullet": bullet}
    found = pictured.undecided(shot, fury, np.where(bullet == 0, 0, -1), background={1})
    band = _square() & ~_square(top=14)
    assert found[band].all() == left_out and found[band].any() == left_out
    assert not found[_square(top=14) & _square()].any()  # where both show the body, nothing is left out


def test_two_bodies_at_the_same_depth_are_a_tie_either_renderer_may_show():
    """Coincident faces of two links (the WSG-50 gripper's motor and hinge): where the pictures show two
    different bodies at depths within 0.1 %, each renderer's rounding chose; at different depths, the
    pictures disagree on something real and are compared."""
    from conformance.apps import pictured

    fury, bullet = np.where(_square(), 0, -1), np.where(_square(), 2, -1)
    for gap, tie in ((1e-5, True), (0.01, False)):
        shot = {"fury_depth": np.where(_square(), 1.0, np.inf), "bullet_depth": np.where(_square(), 1.0 + gap, np.inf),
                "bullet": bullet}
        assert pictured.undecided(shot, fury, bullet, background=set())[_square()].all() == tie


@pytest.mark.parametrize("back, left_out", [(True, True), (False, False)])
def test_a_face_fury_shows_from_its_back_where_pybullet_shows_nothing_is_left_out(back, left_out):
    """pyBullet's renderer culls back faces; FURY 2's meshes are two-sided: a single-sided sheet seen from below
    (pybullet_data's cloth_z_up.urdf) shows in FURY's picture only. Its front, where pyBullet shows nothing, is
    a body drawn where pyBullet has none, and is compared."""
    from conformance.apps import pictured

    fury, bullet = np.where(_square(), 0, -1), np.full(_square().shape, -1)
    shot = {"fury_depth": np.where(_square(), 1.0, np.inf), "bullet_depth": np.full(fury.shape, np.inf),
            "bullet": bullet, "fury_back": _square() & back}
    assert pictured.undecided(shot, fury, bullet, background=set())[_square()].all() == left_out


def test_a_body_welded_to_a_link_not_drawn_names_no_other_shape():
    """A base and a link on a fixed joint are one rigid drawing (:mod:`conformance.apps.welds`): with the link
    drawn nowhere (``drawn`` says so), what the base's actor shows may be part of the link's drawing, so its
    failing picture names no other shape; the same base alone does (issue 48: right or silent)."""
    pos, orn = motion()
    link = Frame(0, 0, 0, "box0 link", 1.0, (("box", tuple(2 * HALF), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)),))
    link_pos = pos + Rotation.from_quat(orn).apply([0.5, 0.0, 0.0])
    flat = [track(draw(pos, orn, CORNERS * np.array([1.0, 1.0, 0.5])))]
    shots = [_shot(_labels(_square(top=15, left=15, side=10), 0), _labels(_square(), 0))]
    welded = _judged(shots, frames=[box_frame(), link], poses=[(pos, orn), (link_pos, orn)], tracks=flat)
    assert not welded.passed and welded.diagnoses == [], welded.message()
    alone = _judged(shots, tracks=flat)
    assert not alone.passed and alone.diagnoses == ["not-its-shape"], alone.message()


def test_a_body_that_never_moves_drawn_as_another_shape_names_no_shape():
    """A fixed base (mass, but its pose constant for the whole run) drawn flattened: every still frame holds what
    never moves alike, so the part of the drawing it holds is no evidence of the shape drawn. Its picture fails
    and names nothing; the same body moving names ``not-its-shape`` (the test above)."""
    pos, orn = motion()
    fixed = (np.broadcast_to(pos[0], pos.shape).copy(), np.broadcast_to(orn[0], orn.shape).copy())
    flat = [track(draw(*fixed, CORNERS * np.array([1.0, 1.0, 0.5])))]
    shots = [_shot(_labels(_square(top=15, left=15, side=10), 0), _labels(_square(), 0))]
    verdict = _judged(shots, poses=[fixed], tracks=flat)
    assert not verdict.passed and verdict.diagnoses == [], verdict.message()
