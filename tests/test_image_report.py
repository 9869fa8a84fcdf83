"""Image-check artefacts on disk and the HTML report over them, from synthetic records and pictures."""

from __future__ import annotations

import json
import re
import shutil

import numpy as np
import pytest

from conformance.errors import InvalidArgument
from conformance.reports import artefacts, report
from conformance.rendering.records import ImageCheck

W, H = 450, 384


def scene_picture(shift=0):
    """A dark scene with a lit ball and a box, the ball moved ``shift`` pixels to the right."""
    y, x = np.mgrid[:H, :W]
    image = np.zeros((H, W, 3), np.uint8)
    image[...] = (28, 32, 40)
    image[y > 300] = (70, 74, 80)  # the floor
    ball = (x - 150 - shift) ** 2 + (y - 200) ** 2 < 50 ** 2
    image[ball] = (200, 60, 50)
    image[(abs(x - 320) < 40) & (abs(y - 250) < 50)] = (60, 120, 200)
    return image


def difference_picture(a, b):
    """Where two pictures differ, bright on black (what a golden check would write)."""
    delta = np.abs(a.astype(int) - b.astype(int)).max(axis=-1)
    out = np.zeros_like(a)
    out[delta > 0] = (255, 0, 255)
    return out


def masks(shift=0):
    """Two silhouettes and their difference, in the colours of ``silhouettes.mask_images``."""
    y, x = np.mgrid[:H, :W]
    pyb = (x - 200) ** 2 + (y - 190) ** 2 < 70 ** 2
    fury = (x - 200 - shift) ** 2 + (y - 190) ** 2 < 70 ** 2
    diff = np.zeros((H, W, 3), np.uint8)
    diff[fury & pyb] = (255, 255, 255)
    diff[fury & ~pyb] = (255, 0, 0)  # only FURY draws the body here
    diff[pyb & ~fury] = (0, 0, 255)  # only pyBullet has it here
    return pyb, fury, diff


def golden(scene="free_fall", frame=60, passed=False, **kw):
    return ImageCheck(kind="golden", scene=scene, frame=frame, passed=passed,
                      message=kw.pop("message", "" if passed else "4.2% of pixels differ (limit 0.5%)"),
                      sync=kw.pop("sync", "reference"),
                      metrics=kw.pop("metrics", {"differing_fraction": 0.042 if not passed else 0.0001,
                                                 "max_channel_difference": 255}),
                      limits=kw.pop("limits", {"differing_fraction": 0.005}),
                      details=kw.pop("details", {"tolerance_set": "same-renderer", "physics": "pass"}),
                      reproduce=kw.pop("reproduce", f"python -m conformance check {scene} --frames {frame} --sync reference"),
                      **kw)


def silhouette(scene="chain", frame=30, passed=False, **kw):
    return ImageCheck(kind="silhouette", scene=scene, frame=frame, passed=passed,
                      message=kw.pop("message", "" if passed else "target 'link2' IoU 0.71 below 0.95"),
                      sync="reference", metrics={"iou": 0.71 if not passed else 0.99}, limits={"iou": 0.95},
                      details={"tolerance_set": "other-renderer", "min_pixels": 20, "targets": [
                          {"target": "link1", "iou": 0.99, "fury_pixels": 1200, "pybullet_pixels": 1210},
                          {"target": "link2", "iou": 0.71, "fury_pixels": 900, "pybullet_pixels": 1150}]},
                      reproduce=f"python -m conformance check {scene} --frames {frame}", **kw)


def golden_pictures(shift=40):
    expected, actual = scene_picture(), scene_picture(shift)
    return {"expected": expected, "actual": actual, "difference": difference_picture(expected, actual)}


def silhouette_pictures(shift=30):
    pyb, fury, diff = masks(shift)
    return {"pybullet_mask": pyb, "fury_mask": fury, "mask_difference": diff}


@pytest.fixture
def worker(monkeypatch):
    """Set the pytest-xdist worker id this process writes records as."""
    def set_worker(name):
        if name is None:
            monkeypatch.delenv("PYTEST_XDIST_WORKER", raising=False)
        else:
            monkeypatch.setenv("PYTEST_XDIST_WORKER", name)
    set_worker(None)
    return set_worker


def demo_run(results, worker):
    """A small run: a failing golden and silhouette, passes of each kind (a golden past its chaotic step
    whose physics differs, with its pictures, as ``--keep-passing`` would keep them)."""
    worker("gw0")
    artefacts.write_artefacts(golden(), results, golden_pictures())
    artefacts.write_artefacts(golden("pile", 90, passed=True,
                                     details={"tolerance_set": "same-renderer", "physics": {
                                         "frame": 90, "chaotic": True, "position": 0.002, "angle": 0.01,
                                         "target": "box3", "ok": False, "position_tolerance": 1e-6,
                                         "angle_tolerance": 1e-5}}),
                              results, {k: v for k, v in golden_pictures(0).items() if k != "difference"})
    worker("gw1")
    artefacts.write_artefacts(silhouette(), results, silhouette_pictures())
    artefacts.write_artefacts(silhouette("chain", 0, passed=True), results)
    artefacts.write_artefacts(ImageCheck("framing", "wrecking_ball", 0, True,
                                         metrics={"smallest_extent": 81.5, "badly_framed": 0.0},
                                         limits={"smallest_extent": 3.0, "badly_framed": 0.0}), results)
    return artefacts.read_records(results)


def test_failures_get_every_picture_under_the_documented_layout(tmp_path, worker):
    record = artefacts.write_artefacts(golden(params={"mass": 2.0}), tmp_path, golden_pictures())
    assert set(record.images) == {"expected", "actual", "difference"}
    for role, relative in record.images.items():
        assert re.fullmatch(rf"golden/free_fall/frame60-[0-9a-f]{{10}}-{role}\.png", relative)
        assert (tmp_path / relative).read_bytes().startswith(b"\x89PNG")
    assert [p.name for p in tmp_path.glob("*.jsonl")] == ["records-main.jsonl"]
    assert artefacts.read_records(tmp_path) == [record]


def test_passing_checks_are_recorded_with_the_pictures_they_are_given(tmp_path, worker):
    quiet = artefacts.write_artefacts(golden(passed=True), tmp_path)
    pictures = golden_pictures(0)
    kept = artefacts.write_artefacts(golden(passed=True, sync="other"), tmp_path,
                                     {"expected": pictures["expected"], "actual": pictures["actual"]})
    assert quiet.images == {}
    assert set(kept.images) == {"expected", "actual"}
    assert len(artefacts.read_records(tmp_path)) == 2


def test_params_and_sync_keep_variants_apart_and_the_layout_stays_stable():
    plain = artefacts.artefact_path(ImageCheck("golden", "chain", 3, False), "actual")
    assert plain.as_posix() == "golden/chain/frame3-actual.png"
    a = artefacts.artefact_path(golden(params={"n": 1}), "actual")
    b = artefacts.artefact_path(golden(params={"n": 2}), "actual")
    assert a != b and a == artefacts.artefact_path(golden(params={"n": 1}), "actual")
    assert artefacts.artefact_path(ImageCheck("golden", "../../etc", 1, False), "actual").parts[:2] == ("golden", "_.._etc")
    with pytest.raises(InvalidArgument, match="fury_mask"):
        artefacts.artefact_path(golden(), "fury_mask")


def test_bad_pictures_are_refused_clearly(tmp_path):
    with pytest.raises(InvalidArgument, match="uint8 of shape"):
        artefacts.write_artefacts(golden(), tmp_path, {"actual": np.zeros((4, 4, 3), np.float64)})


def test_identical_pictures_give_identical_bytes_and_no_temp_files_remain(tmp_path):
    picture = scene_picture(7)
    first = artefacts.write_png(tmp_path / "a" / "one.png", picture)
    second = artefacts.write_png(tmp_path / "b" / "two.png", picture.copy())
    artefacts.write_png(first, picture)  # overwriting in place goes through a temporary file too
    assert first.read_bytes() == second.read_bytes()
    assert b"tIME" not in first.read_bytes() and b"tEXt" not in first.read_bytes()
    assert sorted(p.name for p in tmp_path.rglob("*") if p.is_file()) == ["one.png", "two.png"]


def test_records_of_several_workers_are_merged_and_corrupt_lines_skipped(tmp_path, worker):
    worker("gw0")
    artefacts.write_artefacts(golden(), tmp_path, golden_pictures())
    worker("gw1")
    artefacts.write_artefacts(silhouette(), tmp_path, silhouette_pictures())
    with open(tmp_path / "records-gw1.jsonl", "a", encoding="utf-8") as fh:
        fh.write('{"kind": "golden", "scene": "half-writ\n')  # a worker killed mid-line
        fh.write('{"kind": "nonsense", "scene": "x", "frame": 1, "passed": true}\n')  # not a kind
        fh.write(json.dumps(golden("late").to_json()) + "\n")
    assert sorted(p.name for p in tmp_path.glob("*.jsonl")) == ["records-gw0.jsonl", "records-gw1.jsonl"]
    with pytest.warns(artefacts.CorruptRecordWarning) as caught:
        records = artefacts.read_records(tmp_path)
    assert [str(w.message).split(": ")[0].rsplit("/", 1)[-1] for w in caught] == ["records-gw1.jsonl:2", "records-gw1.jsonl:3"]
    assert [(r.kind, r.scene) for r in records] == [("golden", "free_fall"), ("silhouette", "chain"), ("golden", "late")]


def test_numpy_numbers_in_a_record_survive_the_round_trip(tmp_path):
    record = golden(metrics={"differing_fraction": np.float32(0.25), "pixels": np.int64(12)})
    artefacts.write_artefacts(record, tmp_path)
    assert artefacts.read_records(tmp_path)[0].metrics == {"differing_fraction": 0.25, "pixels": 12}


def test_clear_removes_a_previous_run_and_nothing_else(tmp_path, worker):
    artefacts.write_artefacts(golden(), tmp_path, golden_pictures())
    (tmp_path / "keep.txt").write_text("mine")
    artefacts.clear(tmp_path)
    assert [p.name for p in tmp_path.iterdir()] == ["keep.txt"]


def test_the_report_is_one_self_contained_page_with_failures_first(tmp_path, worker):
    records = demo_run(tmp_path, worker)
    path = report.write_report(records, tmp_path, title="Image checks <sync 'x'>",
                               header_lines=["sync under test: reference", "tolerance set: same-renderer"])
    page = path.read_text(encoding="utf-8")
    assert path == tmp_path / "report.html"
    assert "http://" not in page and "https://" not in page and 'src="file' not in page
    assert not re.search(r'<(link|script)[^>]+(href|src)=', page)  # no external stylesheet or script
    assert page.count('src="data:image/png;base64,') == 8  # two failures' three pictures, a pass's two
    statuses = re.findall(r'data-status="(\w+)"', page)
    assert statuses == ["failed", "failed", "passed", "passed", "passed"]
    assert "2 failed" in page and "5 checks with pictures" in page
    assert "Image checks &lt;sync &#x27;x&#x27;&gt;" in page
    assert "tolerance set: other-renderer" in page
    assert "physics: differs at &#x27;box3&#x27;: 0.002 m (tolerance 1e-06 m)" in page
    assert "chaotic" in page and "physics: pass" in page
    assert "<code>python -m conformance check free_fall --frames 60 --sync reference</code>" in page
    assert sorted(p.name for p in tmp_path.rglob(".*")) == []  # no temporary file left behind


def test_the_report_escapes_everything_from_a_record(tmp_path):
    evil = golden(scene="<b>s</b>", message="<script>alert(1)</script>", reproduce="echo '<x>' && rm",
                  params={"<p>": "</code>"}, details={"tolerance_set": '"><img src=x>', "note": "<i>n</i>"})
    page = report.render_report([evil], tmp_path)
    assert "<script>alert" not in page and "&lt;script&gt;alert(1)&lt;/script&gt;" in page
    assert "<b>s</b>" not in page and '"><img' not in page and "<i>n</i>" not in page
    assert "echo &#x27;&lt;x&gt;&#x27; &amp;&amp; rm" in page
    assert page.count("<script>") == 1  # the page's own filter script, nothing else


def test_the_report_survives_missing_pictures_and_empty_runs_and_stays_in_its_directory(tmp_path):
    (tmp_path / "secret.png").write_bytes(b"\x89PNG not for the page")
    record = golden(images={"actual": "golden/free_fall/frame60-actual.png", "expected": "../secret.png"})
    page = report.render_report([record], tmp_path / "results")
    assert page.count("picture missing") == 2 and "base64" not in page
    assert "No checks with pictures were recorded" in report.render_report([], tmp_path)


@pytest.mark.skipif(shutil.which("chromium") is None, reason="chromium is not installed")
def test_a_screenshot_of_the_report(tmp_path, worker):
    from PIL import Image

    from conformance.reports.screenshot import screenshot

    page = report.write_report(demo_run(tmp_path, worker), tmp_path)
    png = screenshot(page, tmp_path / "shot.png", size=(800, 600))
    assert Image.open(png).size == (800, 600)
