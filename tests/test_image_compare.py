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


def test_flips_error_reaches_no_farther_than_the_kit_evaluates():
    """compare.flip_mean evaluates FLIP only within FLIP_REACH of a changed pixel: a one-pixel change must
    give no error beyond it (at flip-evaluator's own default viewing conditions)."""
    import flip_evaluator

    from conformance.rendering.compare import FLIP_REACH

    rng = np.random.default_rng(0)
    picture = rng.random((80, 80, 3)).astype(np.float32)
    changed = picture.copy()
    changed[40, 40] = 1 - changed[40, 40]
    errors = np.asarray(flip_evaluator.evaluate(picture, changed, "LDR", applyMagma=False)[0]).reshape(80, 80)
    rows, columns = np.nonzero(errors)
    reach = max(np.abs(rows - 40).max(), np.abs(columns - 40).max())
    assert 0 < reach <= FLIP_REACH, f"a one-pixel change has FLIP errors {reach} pixels away, but should within {FLIP_REACH}"


@pytest.mark.parametrize("seed", range(4))
def test_flip_mean_is_the_whole_pictures_mean(seed):
    """The regions-only FLIP mean equals one evaluation of the whole picture: scattered pixels, a block, an
    edge of the picture."""
    import flip_evaluator

    from conformance.rendering.compare import flip_mean

    rng = np.random.default_rng(seed)
    expected = rng.integers(0, 256, (96, 128, 3), dtype=np.uint8)
    actual = expected.copy()
    count = rng.integers(1, 40)
    rows, columns = rng.integers(0, 96, count), rng.integers(0, 128, count)
    actual[rows, columns] = rng.integers(0, 256, (count, 3))
    actual[0:10, 100:128] = rng.integers(0, 256, 3)  # a block at the picture's edge
    whole = float(flip_evaluator.evaluate(expected.astype(np.float32) / 255, actual.astype(np.float32) / 255, "LDR",
                                          applyMagma=False)[1])
    assert flip_mean(expected, actual) == pytest.approx(whole, rel=1e-4)
    assert flip_mean(expected, expected.copy()) == 0.0
