"""Golden-image comparison: the tolerance sets pass benign changes and fail real errors, on real renders."""

import numpy as np
import pytest

from conformance import backends, sync
from conformance.errors import ImageSizeMismatch, InvalidArgument
from conformance.rendering.compare import (OTHER_RENDERER, SAME_RENDERER, compare_images, difference_image,
                                           tolerance)
from conformance.rendering.measure_tolerances import ERRORS, perturbed, pick_target, with_noise
from conformance.sync.runner import running

SCENES = ("sliding_box", "free_fall", "domino")


def check(expected, actual, limits, *, passes):
    __tracebackhide__ = True
    record = compare_images(expected, actual, limits)
    if record.passed != passes:
        pytest.fail(f"expected {'pass' if passes else 'fail'} under {limits.name}: {record.message} {record.metrics}")


@pytest.fixture(scope="module", params=SCENES)
def renders(request):
    images = {}
    with running(request.param, sync.load("reference")) as run:
        run.advance(30)
        camera, size = run.scene.camera, run.scene.image_size
        images["base"] = backends.render(run.drawing, camera, size)
        images["again"] = backends.render(run.drawing, camera, size)
        images["msaa_off"] = backends.render(run.drawing, camera, size, multisamples=0)
        for kind in ERRORS:
            with perturbed(run, pick_target(run, size, turning=kind == "turned"), kind):
                images[kind] = backends.render(run.drawing, camera, size)
    return images


def test_rerender_passes_both_sets(renders):
    check(renders["base"], renders["again"], SAME_RENDERER, passes=True)
    check(renders["base"], renders["again"], OTHER_RENDERER, passes=True)


def test_noise_and_multisampling_pass_other_renderer(renders):
    check(renders["base"], with_noise(renders["base"]), OTHER_RENDERER, passes=True)
    check(renders["base"], renders["msaa_off"], OTHER_RENDERER, passes=True)


@pytest.mark.parametrize("kind", ERRORS)
def test_errors_fail_same_renderer(renders, kind):
    check(renders["base"], renders[kind], SAME_RENDERER, passes=False)


@pytest.mark.parametrize("kind", ERRORS)
def test_errors_fail_other_renderer(renders, kind):
    check(renders["base"], renders[kind], OTHER_RENDERER, passes=False)


def test_difference_image_marks_changed_pixels(renders):
    picture = difference_image(renders["base"], renders["moved"])
    assert picture.shape == renders["base"].shape and picture.dtype == np.uint8
    changed = (renders["base"] != renders["moved"]).any(axis=-1)
    assert (picture[changed][:, 1] < picture[~changed][:, 1].min()).all()  # marked pixels lose green


def test_size_mismatch_is_its_own_error():
    with pytest.raises(ImageSizeMismatch, match="450x384"):
        compare_images(np.zeros((384, 450, 3), np.uint8), np.zeros((380, 450, 3), np.uint8), SAME_RENDERER)


@pytest.mark.parametrize("overrides, words", [
    ({"pixel_threshold": "lots"}, ["pixel_threshold='lots'", "str"]),
    ({"pixel_threshold": 300}, ["pixel_threshold=300", "int", "0 to 255"]),
    ({"max_differing_fraction": -0.1}, ["max_differing_fraction=-0.1", "float"]),
    ({"block": 2.5}, ["block=2.5", "float"]),
    ({"colour": "1"}, ["colour='1'", "str", "pixel_threshold"]),
])
def test_bad_tolerances_name_argument_value_and_type(overrides, words):
    with pytest.raises(InvalidArgument) as caught:
        tolerance("other-renderer", **overrides)
    for word in words:
        assert word in str(caught.value)


def test_tolerance_by_name_with_overrides_from_strings():
    assert tolerance("other-renderer", pixel_threshold="16").pixel_threshold == 16
    assert tolerance("same-renderer") is SAME_RENDERER or tolerance("same-renderer") == SAME_RENDERER
    with pytest.raises(InvalidArgument, match="tolerance='nearby' \\(str\\)"):
        tolerance("nearby")
