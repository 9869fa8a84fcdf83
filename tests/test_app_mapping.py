"""An app's mapping (``my_sim.mapping.py`` beside ``my_sim.py``) makes the app judgement exact.

Without it a vertex passes when *some* frame holds it; two identical bodies whose actors are swapped
are each drawn rigidly on a body's shape, so attachment alone accepts them (the colours are wrong on
screen). With the mapping each range must be held by the frame it names: the swap fails, naming both
bodies. A mapping that cannot be used stops the run with one paragraph naming the entry.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from conformance import apps, backends
from conformance.apps.judge import judge as judge_recording

import app_recordings as rec
import app_sources

ACTOR, BODY = ("ball_actor", "ball") if backends.NAME == "vtk" else ("box", "body")


def _two_boxes(swapped: bool, mapping: list):
    frames = [rec.box_frame(0), rec.box_frame(1)]
    poses = [rec.motion(seed=0), rec.motion(seed=1, offset=(1.0, 0.0, 0.0))]
    drawn = [poses[1], poses[0]] if swapped else poses
    tracks = [rec.track(rec.draw(*drawn[0]), label="red_box"), rec.track(rec.draw(*drawn[1]), label="blue_box")]
    recording = rec.recording(frames, poses, tracks)
    recording.mapping = mapping
    return recording


MAPPING = [{"actor": 0, "start": 0, "stop": 8, "frame": 0}, {"actor": 1, "start": 0, "stop": 8, "frame": 1}]


def test_swapped_actors_pass_without_a_mapping_and_fail_with_one():
    unmapped = judge_recording(_two_boxes(True, []))
    assert all(v.passed for v in unmapped.values()), {k: v.message() for k, v in unmapped.items() if not v.passed}
    attached = judge_recording(_two_boxes(True, MAPPING))["attached"]
    assert not attached.passed
    message = attached.message()
    assert re.search(r"red_box \(\w+\) vertices 0:8, drawn for body 0 base \(box0\) by the app's mapping: not held by it "
                     r"from tick 1: .* m from where it carries them \(allowed .* m\).*; they are held by body 1 base "
                     r"\(box1\) instead", message), message
    assert "other-body" in attached.diagnoses


def test_a_right_app_with_its_mapping_passes():
    verdicts = judge_recording(_two_boxes(False, MAPPING))
    assert all(v.passed for v in verdicts.values()), {k: v.message() for k, v in verdicts.items() if not v.passed}


def test_a_mapping_decides_what_attachment_cannot():
    # Two boxes moving as one (the same motion, side by side): each actor is held by both frames alike.
    frames = [rec.box_frame(0), rec.box_frame(1)]
    motion = rec.motion(seed=3)
    tracks = [rec.track(rec.draw(*motion), label="red_box")]
    unmapped = rec.recording(frames, [motion, motion], tracks)
    assert "held equally by two frames" in judge_recording(unmapped)["attached"].message() or \
        any("held equally" in n for n in judge_recording(unmapped)["attached"].notes)
    mapped = rec.recording(frames, [motion, motion], tracks)
    mapped.mapping = [{"actor": 0, "start": 0, "stop": 8, "frame": 1}]
    verdict = judge_recording(mapped)["attached"]
    assert verdict.passed and not any("held equally" in n for n in verdict.notes), verdict.notes


def _copy(tmp_path, mapping_text: str, source: str = app_sources.SOURCE) -> Path:
    app = tmp_path / "sim.py"
    app.write_text(source, encoding="utf-8")
    (tmp_path / "sim.mapping.py").write_text(mapping_text, encoding="utf-8")
    return app


def test_an_app_is_judged_with_the_mapping_beside_it(tmp_path):
    app = _copy(tmp_path, "from conformance.apps.mapping import Draws\n\n"
                          f"def mapping(app):\n    return [Draws(app.{ACTOR}, app.{BODY})]\n")
    result = apps.check_app(app, ticks=10)
    assert result.recording.mapping == [{"actor": 0, "start": 0, "stop": result.recording.actors[0].vertices.shape[1],
                                         "frame": 0}]
    assert all(v.passed for v in result.verdicts.values()), result.verdicts


def test_a_mapping_without_a_client_names_the_first_client_with_bodies(tmp_path):
    """The app keeps an empty client 0 and simulates on client 1: ``Draws`` without ``client`` is its box
    there, not a body 'on client 0 that does not exist'."""
    app = _copy(tmp_path, "from conformance.apps.mapping import Draws\n\n"
                          f"def mapping(app):\n    return [Draws(app.{ACTOR}, app.{BODY})]\n",
                source=app_sources.on_a_client_of_its_own())
    result = apps.check_app(app, ticks=10)
    assert [(f.client, f.body) for f in result.recording.frames] == [(1, 0)]
    assert [m["frame"] for m in result.recording.mapping] == [0]
    assert all(v.passed for v in result.verdicts.values()), result.verdicts


@pytest.mark.parametrize("text, needle", [
    ("def mapping(app):\n    raise KeyError('bricks')\n", r"sim\.mapping\.py: the mapping raised KeyError: 'bricks'"),
    (f"def mapping(app):\n    return [(app.{BODY}, 0)]\n", r"entry 0 \(\(0, 0\)\) is a tuple, but should be a Draws"),
    (f"from conformance.apps.mapping import Draws\ndef mapping(app):\n    return [Draws(object(), app.{BODY})]\n",
     r"entry 0 .*: its actor is not one the ShowManager's scene draws"),
    (f"from conformance.apps.mapping import Draws\ndef mapping(app):\n    return [Draws(app.{ACTOR}, 7)]\n",
     r"entry 0 .*: body 7 link -1 on client \d+ does not exist"),
    (f"from conformance.apps.mapping import Draws\ndef mapping(app):\n    return [Draws(app.{ACTOR}, app.{BODY}, vertices=(5, 99999))]\n",
     r"vertices=\(5, 99999\), but should lie within the actor's \d+ vertices"),
    ("MAPPING = {}\n", r"defines no function mapping\(app\)"),
])
def test_a_mapping_that_cannot_be_used_is_one_paragraph(tmp_path, text, needle):
    with pytest.raises(apps.AppFailed) as err:
        apps.check_app(_copy(tmp_path, text), ticks=5)
    message = str(err.value)
    assert re.search(needle, message), message
    assert "Traceback" not in message and "\n" not in message.strip(), message


def test_a_mapping_file_is_never_taken_for_an_app(tmp_path):
    from conformance.commands.app_table import example_paths

    _copy(tmp_path, "def mapping(app):\n    return []\n")
    assert example_paths([tmp_path]) == [tmp_path / "sim.py"]
