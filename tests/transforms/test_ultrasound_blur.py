import math
import os
import pickle

import numpy as np
import pytest
import torch
from reference_em_blur import ultrasound_blur_reference

from lerobot_phantom.transforms import ultrasound_blur as ultrasound_blur_module
from lerobot_phantom.transforms.ultrasound_blur import (
    SNAP,
    UltrasoundBlur,
    _general_blur,
    _linear_blur,
    _linear_geometry,
    ultrasound_blur,
)

os.environ.setdefault("HF_HUB_OFFLINE", "1")


def _random_uint8(shape, seed):
    return torch.randint(0, 256, shape, dtype=torch.uint8, generator=torch.Generator().manual_seed(seed))


def _reference(img: torch.Tensor, dx, dy, theta_deg=0.0, scale=0.0, **kwargs) -> torch.Tensor:
    """The literal reference takes the paper code's frame: its dx moves rows, i.e. our dy."""
    out = ultrasound_blur_reference(img.permute(1, 2, 0).numpy(), dy, dx, theta_deg, scale, **kwargs)
    return torch.from_numpy(np.ascontiguousarray(out)).permute(2, 0, 1)


def _max_grey_diff(a: torch.Tensor, b: torch.Tensor) -> int:
    return int((a.int() - b.int()).abs().max())


@pytest.mark.parametrize("displacement", [5.0, 10.0, 20.0])
@pytest.mark.parametrize("shape", [(3, 64, 48), (3, 33, 57)])
def test_paper_levels_match_reference_within_one_grey_level(displacement, shape):
    img = _random_uint8(shape, seed=int(displacement) + shape[1])
    expected = _reference(img, displacement, displacement, snap=SNAP)
    out = ultrasound_blur(img, displacement, displacement)
    # the reference truncates the mean to uint8 (numpy astype), the kernel rounds it: one grey level at most
    assert _max_grey_diff(out, expected) <= 1
    assert (out != img).float().mean() > 0.9


@pytest.mark.parametrize(
    ("dx", "dy", "theta_deg", "scale"),
    [
        (-7.5, 3.2, 0.0, 0.0),
        (0.0, 6.0, 0.0, 0.0),
        (4.0, 0.0, 0.0, 0.0),
        (5.0, 5.0, 10.0, 0.0),
        (3.0, -4.0, 0.0, 0.1),
        (0.0, 0.0, 15.0, 0.05),
        (-2.5, -9.0, -8.0, 0.0),
        (150.0, 150.0, 0.0, 0.0),  # beyond the 100-sample cap of the paper's code
    ],
)
def test_general_settings_match_reference_within_one_grey_level(dx, dy, theta_deg, scale):
    img = _random_uint8((3, 40, 31), seed=7)
    expected = _reference(img, dx, dy, theta_deg, scale, snap=SNAP)
    assert _max_grey_diff(ultrasound_blur(img, dx, dy, theta_deg, scale), expected) <= 1


def test_literal_float_round_off_only_moves_paths_by_one_pixel():
    """The paper's literal float64 arithmetic truncates ``R*cos(alpha) + c0`` one pixel short for some pixels.

    Where the literal coordinates equal the exact ones (recomputed here with the same ``math`` calls), the literal
    reference and the kernel agree within one grey level; elsewhere the whole path is offset by one pixel, which
    is round-off noise, not the algorithm. Such pixels are a minority.
    """
    img = _random_uint8((3, 48, 40), seed=3)
    d = 10.0
    literal = _reference(img, d, d)
    ours = ultrasound_blur(img, d, d)
    h, w = 48, 40
    c0, c1 = h // 2, w // 2
    length, delta = math.hypot(d, d), math.atan2(d, d)
    x_cos, y_sin = length * math.cos(delta), length * math.sin(delta)
    moved = np.zeros((h, w), dtype=bool)
    for row in range(h):
        for col in range(w):
            radius, alpha = math.hypot(row - c0, col - c1), math.atan2(col - c1, row - c0)
            end = max(
                abs(radius * math.cos(alpha) + x_cos + c0 - row),
                abs(radius * math.sin(alpha) + y_sin + c1 - col),
            )
            moved[row, col] = int(end) != int(d) or any(
                int(radius * math.cos(alpha) + i / d * x_cos + c0) != row + i
                or int(radius * math.sin(alpha) + i / d * y_sin + c1) != col + i
                for i in range(int(d) + 1)
            )
    assert 0 < moved.mean() < 0.25
    diff = (ours.int() - literal.int()).abs().amax(dim=0).numpy()
    assert diff[~moved].max() <= 1
    assert diff[moved].max() > 1  # the round-off is visible, which is why the kernel snaps


def test_paper_2x2_block_copy_is_fixed():
    img = _random_uint8((3, 32, 32), seed=5)
    paper = _reference(img, 5.0, 5.0, paper_block2x2=True, snap=SNAP)
    every_pixel = _reference(img, 5.0, 5.0, snap=SNAP)
    blocks = paper.reshape(3, 16, 2, 16, 2)
    assert (
        blocks == blocks[:, :, :1, :, :1]
    ).all()  # the released code: constant 2x2 blocks, half resolution
    ours = ultrasound_blur(img, 5.0, 5.0)
    assert _max_grey_diff(ours, every_pixel) <= 1
    assert _max_grey_diff(ours, paper) > 1
    ours_blocks = ours.reshape(3, 16, 2, 16, 2)
    assert not (ours_blocks == ours_blocks[:, :, :1, :, :1]).all()


def test_vertical_blur_has_no_division_by_zero_and_is_a_column_average():
    img = torch.rand(1, 3, 12, 5, generator=torch.Generator().manual_seed(0))
    out = ultrasound_blur(img, 0.0, 3.0)
    expected = torch.stack([img[..., r : min(r + 4, 12), :].mean(dim=-2) for r in range(12)], dim=-2)
    torch.testing.assert_close(out, expected)


def test_fast_linear_path_equals_general_path():
    img = torch.rand(2, 3, 29, 35, generator=torch.Generator().manual_seed(1))
    for d_row, d_col in ((5.0, 5.0), (7.5, -3.2), (-11.0, 0.4), (0.5, 0.9), (-2.5, -2.5)):
        torch.testing.assert_close(
            _linear_blur(img, d_row, d_col), _general_blur(img, d_row, d_col, 0.0, 0.0)
        )


def test_intensity_zero_and_sub_pixel_displacements_are_identity():
    img = _random_uint8((2, 3, 30, 30), seed=2)
    torch.testing.assert_close(UltrasoundBlur(0.0)(img), img, atol=0, rtol=0)
    torch.testing.assert_close(ultrasound_blur(img, 0.9, -0.9), img, atol=0, rtol=0)


@pytest.mark.parametrize(
    ("height", "width", "level", "dx", "dy"),
    [
        (256, 256, "weak", 5.0, 5.0),
        (256, 256, "strong", 20.0, 20.0),
        (96, 96, "strong", 7.5, 7.5),
        (480, 640, "medium", 25.0, 18.75),
    ],
)
def test_displacement_is_defined_at_256_and_scales_with_the_image(height, width, level, dx, dy):
    params = UltrasoundBlur(level).sample_params(1, height, width)
    assert params["dx"].item() == pytest.approx(dx)
    assert params["dy"].item() == pytest.approx(dy)
    assert params["theta_deg"].item() == 0 and params["scale"].item() == 0


def test_class_at_medium_matches_reference_on_a_256_image():
    img = _random_uint8((3, 256, 64), seed=9)  # 256 rows: the vertical displacement is exactly 10 px
    out = UltrasoundBlur("medium")(img)
    assert _max_grey_diff(out, _reference(img, 10.0 * 64 / 256, 10.0, snap=SNAP)) <= 1


def test_batch_with_per_sample_parameters_matches_single_calls():
    imgs = _random_uint8((5, 3, 24, 20), seed=4)
    attack = UltrasoundBlur("random", random_direction=True, rotation_deg=6.0)
    params = attack.sample_params(5, 24, 20, generator=torch.Generator().manual_seed(0))
    assert len(set(params["dx"].tolist())) == 5
    out = attack.apply_params(imgs, params)
    for i in range(5):
        single = {k: v[i : i + 1] for k, v in params.items()}
        torch.testing.assert_close(
            out[i : i + 1], attack.apply_params(imgs[i : i + 1], single), atol=0, rtol=0
        )
    shared = attack.apply_params(imgs, {k: v[:1] for k, v in params.items()})  # leading dim 1 broadcasts
    for i in range(5):
        torch.testing.assert_close(
            shared[i], attack.apply_params(imgs[i], {k: v[:1] for k, v in params.items()})
        )


def test_random_direction_keeps_the_paper_path_length():
    params = UltrasoundBlur("strong", random_direction=True).sample_params(
        64, 256, 256, generator=torch.Generator().manual_seed(0)
    )
    torch.testing.assert_close(
        torch.hypot(params["dx"], params["dy"]), torch.full((64,), 20 * math.sqrt(2), dtype=torch.float64)
    )
    with pytest.raises(ValueError, match="Generator"):
        UltrasoundBlur("strong", random_direction=True).sample_params(2, 32, 32)


def test_layouts_dtypes_and_tiny_images():
    attack = UltrasoundBlur("strong")
    for img in (
        _random_uint8((3, 1, 1), 0),
        _random_uint8((1, 7, 3), 1),
        _random_uint8((2, 4, 15, 9), 2),
        torch.rand(2, 2, 3, 11, 13, dtype=torch.float64, generator=torch.Generator().manual_seed(0)),
    ):
        out = attack(img)
        assert out.shape == img.shape and out.dtype == img.dtype
        if img.is_floating_point():
            assert out.min() >= 0 and out.max() <= 1
    rgba = _random_uint8((4, 20, 20), 3)
    torch.testing.assert_close(attack(rgba)[3], rgba[3], atol=0, rtol=0)


def test_same_seed_same_output_and_pickle_round_trip():
    img = _random_uint8((4, 3, 32, 32), 6)
    a = UltrasoundBlur("random", seed=1, random_direction=True)
    b = pickle.loads(pickle.dumps(UltrasoundBlur("random", seed=1, random_direction=True)))
    torch.testing.assert_close(a(img), b(img), atol=0, rtol=0)
    torch.testing.assert_close(a(img), b(img), atol=0, rtol=0)  # the generators advance in step


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"dx": float("nan"), "dy": 1.0}, "dx"),
        ({"dx": torch.tensor([1.0, 2.0, 3.0]), "dy": 1.0}, "one value"),
    ],
)
def test_bad_parameters_raise(kwargs, match):
    with pytest.raises(ValueError, match=match):
        ultrasound_blur(_random_uint8((2, 3, 8, 8), 0), **kwargs)
    with pytest.raises(ValueError, match="radial_scale"):
        UltrasoundBlur(radial_scale=2.0)


def test_full_hd_frame_keeps_shape_and_caps_the_path_at_100_samples():
    frame = _random_uint8((3, 1080, 1920), seed=11)
    attack = UltrasoundBlur("strong")
    params = attack.sample_params(1, 1080, 1920)
    assert params["dx"].item() == pytest.approx(150.0) and params["dy"].item() == pytest.approx(84.375)
    out = attack.apply_params(frame, params)
    assert out.shape == frame.shape and out.dtype == frame.dtype
    # with 101 samples the top-left pixel averages the in-bounds part of its path: rows/cols i * (84.375, 150) / 100
    samples = [
        frame[:, int(i * 0.84375 + SNAP), int(i * 1.5 + SNAP)].double() for i in range(101) if i * 1.5 < 1920
    ]
    torch.testing.assert_close(out[:, 0, 0].double(), torch.stack(samples).mean(0).round(), atol=1, rtol=0)


def test_random_draws_the_authors_integer_displacements():
    """ "random" = the authors' training: d = randint(5, 20) px at the 256x256 reference, P(d < 10) = 5/16."""
    params = UltrasoundBlur("random").sample_params(
        4000, 256, 256, generator=torch.Generator().manual_seed(0)
    )
    d = params["dx"]
    torch.testing.assert_close(d, params["dy"])
    assert set(d.tolist()) == set(range(5, 21))  # whole pixels: the level map's round trip is snapped
    assert float((d < 10).double().mean()) == pytest.approx(5 / 16, abs=0.03)
    half = UltrasoundBlur("random").sample_params(8, 128, 128, generator=torch.Generator().manual_seed(0))
    torch.testing.assert_close(half["dx"] * 2, d[:8])  # same draws, scaled with the image


@pytest.mark.parametrize("random_direction", [False, True])
def test_uint8_path_is_the_exactly_rounded_mean_for_mixed_displacements(random_direction):
    """The uint8 kernel sums in int16 and divides once: equal to the float64 mean of the 0-255 values rounded half
    to even, per sample, whatever the grouping of a batch with several displacements (box and strided paths)."""
    images = _random_uint8((6, 3, 40, 48), 21)
    attack = UltrasoundBlur("random", random_direction=random_direction, seed=4)
    params = attack.sample_params(6, 40, 48, generator=torch.Generator().manual_seed(9))
    assert len(set(params["dx"].tolist())) > 1  # several groups
    out = attack.apply_params(images, params)
    for i in range(6):
        d_row, d_col = float(params["dy"][i]), float(params["dx"][i])
        expected = torch.round(_linear_blur(images[i : i + 1].double(), d_row, d_col)).to(torch.uint8)
        assert torch.equal(out[i : i + 1], expected), f"sample {i} (d_row={d_row:.3f}, d_col={d_col:.3f})"


def test_float_box_paths_in_chunks_equal_the_general_path_per_sample(monkeypatch):
    """Float box paths (diagonal, vertical, horizontal) are summed by one reduction over a padded buffer, a few
    images at a time: a batch whose displacements interleave (groups of non-consecutive samples, chunks of two)
    gives every sample the general path's mean."""
    images = torch.rand(7, 3, 33, 41, generator=torch.Generator().manual_seed(5), dtype=torch.float64)
    monkeypatch.setattr(ultrasound_blur_module, "_FLOAT_BOX_CHUNK_ELEMENTS", 2 * images[0].numel())
    d_col = torch.tensor([3.0, 0.0, 3.0, 6.0, 0.0, 3.0, 6.0], dtype=torch.float64)
    d_row = torch.tensor([3.0, 5.0, 3.0, 0.0, 5.0, 3.0, 6.0], dtype=torch.float64)
    out = ultrasound_blur_module.ultrasound_blur_float(images, d_col, d_row, upper=1.0)
    for i in range(7):
        d = (float(d_row[i]), float(d_col[i]))
        assert _linear_geometry(33, 41, *d)[1] is not None  # a box path
        expected = _general_blur(images[i : i + 1], *d, 0.0, 0.0)
        torch.testing.assert_close(out[i : i + 1], expected, msg=f"sample {i} (d_row, d_col = {d})")


def test_uint8_box_paths_in_padded_chunks_are_the_exactly_rounded_mean(monkeypatch):
    """uint8 box paths (diagonal, vertical, horizontal) are summed by doubling in int16 buffers zero-padded by the
    path's length, a few images at a time: with interleaved displacements (groups of non-consecutive samples, chunks
    of two, stale scratch from the previous chunk and group) every sample is its float64 mean rounded half to even."""
    images = _random_uint8((7, 3, 33, 41), 23)
    monkeypatch.setattr(ultrasound_blur_module, "_CHUNK_ELEMENTS", 2 * images[0].numel())
    d_col = torch.tensor([3.0, 0.0, 3.0, 6.0, 0.0, 3.0, 17.0], dtype=torch.float64)
    d_row = torch.tensor([3.0, 5.0, 3.0, 0.0, 5.0, 3.0, 17.0], dtype=torch.float64)
    out = ultrasound_blur_module.ultrasound_blur_float(images, d_col, d_row)
    for i in range(7):
        d = (float(d_row[i]), float(d_col[i]))
        assert _linear_geometry(33, 41, *d)[1] is not None  # a box path
        expected = torch.round(_general_blur(images[i : i + 1].double(), *d, 0.0, 0.0)).to(torch.uint8)
        assert torch.equal(out[i : i + 1], expected), f"sample {i} (d_row, d_col = {d})"


def test_the_blur_in_linear_light_sweeps_one_way_as_the_papers_does():
    """``gamma=1`` averages the same pixel values as the paper's blur, along the same one-way path from the pixel to
    the full displacement (a centred path would move the image by half the displacement: 10 px at strong on 256);
    the two sample the segment differently (the paper at whole pixels i / N, this at midpoints): 1.0 grey level
    apart on average on this smooth image, 26 along a centred path. The border is left out: the paper drops samples
    outside the image, this repeats it."""
    generator = torch.Generator().manual_seed(0)
    coarse = torch.rand(1, 3, 16, 16, generator=generator)
    image = torch.nn.functional.interpolate(coarse, size=(256, 256), mode="bilinear", align_corners=False)[0]
    paper = UltrasoundBlur("strong")(image)
    in_pixel_values = UltrasoundBlur("strong", gamma=1.0)(image)
    interior = (slice(None), slice(0, -24), slice(0, -24))
    assert float((in_pixel_values - paper)[interior].abs().mean()) < 2.0 / 255


@pytest.mark.parametrize(("height", "width"), [(480, 640), (640, 480), (48, 64)])
def test_a_measured_displacement_grows_with_the_intensity_and_keeps_its_direction(height, width):
    """``displacement_per_intensity_px`` (what lerobot-phantom-calibrate fits): reference pixels of the longer side
    at intensity 1, scaled alike on both axes, so a measured direction survives a non-square frame (the paper's
    diagonal is scaled per axis instead)."""
    longer = max(height, width) / 256
    for s in (0.0, 0.5, 1.0):
        params = UltrasoundBlur(s, displacement_per_intensity_px=[8.0, -4.0]).sample_params(2, height, width)
        torch.testing.assert_close(params["dx"], torch.full((2,), 8.0 * s * longer, dtype=torch.float64))
        torch.testing.assert_close(params["dy"], torch.full((2,), -4.0 * s * longer, dtype=torch.float64))
    turned = UltrasoundBlur(1.0, displacement_per_intensity_px=(8.0, -4.0), random_direction=True)
    params = turned.sample_params(64, height, width, generator=torch.Generator().manual_seed(0))
    lengths = torch.hypot(params["dx"], params["dy"])
    torch.testing.assert_close(
        lengths, torch.full((64,), math.hypot(8.0, -4.0) * longer, dtype=torch.float64)
    )
    assert float(torch.atan2(params["dy"], params["dx"]).std()) > 1.0  # turned, not kept


def test_a_measured_blur_is_sampled_continuously_as_the_calibration_fits_it():
    """A measured sub-pixel path is the bilinear line blur along ``[0, d]`` (``physics.line_blur``, the frame model
    ``lerobot-phantom-calibrate`` fits), not the paper code's whole-pixel samples, which would shift it towards the
    pixel; uint8 frames take the same float path, rounded once. Zero intensity is the identity."""
    from lerobot_phantom.transforms import physics

    generator = torch.Generator().manual_seed(3)
    coarse = torch.rand(2, 3, 8, 10, generator=generator)
    image = torch.nn.functional.interpolate(coarse, size=(48, 64), mode="nearest")
    attack = UltrasoundBlur(0.7, displacement_per_intensity_px=(31.0, -22.5))
    params = attack.sample_params(2, 48, 64)
    dx, dy = params["dx"].float(), params["dy"].float()
    offsets = physics.attack_blur_offsets("uniform", physics.blur_taps(float(dx[0]), float(dy[0])))
    expected = physics.line_blur(image, dx, dy, offsets)
    torch.testing.assert_close(attack.apply_params(image, params), expected, atol=1e-6, rtol=0)
    paper = ultrasound_blur(image, dx, dy)  # the same displacement at whole pixels
    assert float((paper - expected).abs().mean()) > 0.01
    as_uint8 = (image * 255).round().to(torch.uint8)
    blurred8 = attack.apply_params(as_uint8, params)
    assert _max_grey_diff(blurred8, (attack.apply_params(as_uint8 / 255.0, params) * 255).round()) == 0
    still = UltrasoundBlur(0.0, displacement_per_intensity_px=(31.0, -22.5))
    assert torch.equal(still(as_uint8), as_uint8)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"displacement_per_intensity_px": "12"}, "two finite numbers"),
        ({"displacement_per_intensity_px": [1.0]}, "two finite numbers"),
        ({"displacement_per_intensity_px": [1.0, float("nan")]}, "two finite numbers"),
        ({"displacement_per_intensity_px": [1.0, "a"]}, "two finite numbers"),
        ({"displacement_per_intensity_px": [1.0, 2.0], "displacement_px": 5.0}, "give one"),
        ({"displacement_per_intensity_px": [1.0, 2.0], "rotation_deg": 5.0}, "linear blur only"),
    ],
)
def test_a_bad_measured_displacement_is_refused(kwargs, match):
    with pytest.raises(ValueError, match=match):
        UltrasoundBlur(**kwargs)
