import os
import pickle

import numpy as np
import pytest
import torch
from drawn_frequencies import assert_frequencies_follow
from reference_em_blur import em_truncation_reference

from lerobot_phantom.transforms.em_truncation import EMTruncation, em_truncation, truncation_row_index

os.environ.setdefault("HF_HUB_OFFLINE", "1")


def _random_uint8(shape, seed):
    return torch.randint(0, 256, shape, dtype=torch.uint8, generator=torch.Generator().manual_seed(seed))


def _hwc(chw: torch.Tensor) -> np.ndarray:
    return chw.permute(1, 2, 0).numpy()


def _chw(hwc: np.ndarray) -> torch.Tensor:
    return torch.from_numpy(np.ascontiguousarray(hwc)).permute(2, 0, 1)


@pytest.mark.parametrize("shape", [(3, 17, 23), (3, 32, 32), (3, 96, 96), (3, 101, 7)])
@pytest.mark.parametrize("ratio", [0.1, 0.2, 0.3, 0.137, 1 / 3])
def test_matches_paper_reference_in_paper_range(shape, ratio):
    img = _random_uint8(shape, seed=shape[1] * 7 + int(ratio * 1000))
    expected_paper = em_truncation_reference(_hwc(img), ratio, paper_start=True)
    expected_fixed = em_truncation_reference(_hwc(img), ratio)
    np.testing.assert_array_equal(expected_paper, expected_fixed)  # the fix changes nothing for r <= 1/3
    torch.testing.assert_close(em_truncation(img, ratio), _chw(expected_paper), atol=0, rtol=0)


@pytest.mark.parametrize("height", [10, 64, 100])  # even: int(h/2) * 2 == h
def test_fix_at_half_ratio_paper_is_identity_ours_is_not(height):
    img = _random_uint8((3, height, 9), seed=height)
    paper = em_truncation_reference(_hwc(img), 0.5, paper_start=True)
    np.testing.assert_array_equal(paper, _hwc(img))  # the paper's defect: ratio 0.5 does nothing
    ours = em_truncation(img, 0.5)
    assert not torch.equal(ours, img)
    torch.testing.assert_close(ours, _chw(em_truncation_reference(_hwc(img), 0.5)), atol=0, rtol=0)
    # the upper half is lost and the lower half appears twice
    half = height // 2
    torch.testing.assert_close(
        ours[:, height - 2 * half : height - half], img[:, height - half :], atol=0, rtol=0
    )


def test_fix_paper_output_grows_above_half_ours_keeps_height():
    img = _random_uint8((3, 40, 8), seed=3)
    assert em_truncation_reference(_hwc(img), 0.45, paper_start=True).shape[0] == 40
    # above 0.5 the released code returns a taller image; we reject such ratios with a clear error
    assert em_truncation_reference(_hwc(img), 0.6, paper_start=True).shape[0] > 40
    with pytest.raises(ValueError, match=r"\[0, 0.5\]"):
        em_truncation(img, 0.6)
    out = em_truncation(img, 0.45)
    assert out.shape == img.shape
    torch.testing.assert_close(out, _chw(em_truncation_reference(_hwc(img), 0.45)), atol=0, rtol=0)


def test_batch_with_per_sample_ratios_is_one_call_equal_to_single_calls():
    imgs = _random_uint8((5, 3, 31, 12), seed=11)
    ratios = torch.tensor([0.0, 0.05, 0.1, 0.25, 0.5])
    out = em_truncation(imgs, ratios)
    for i in range(5):
        torch.testing.assert_close(out[i], em_truncation(imgs[i], float(ratios[i])), atol=0, rtol=0)
    torch.testing.assert_close(out[0], imgs[0], atol=0, rtol=0)


def test_row_index_is_a_permutation_free_gather_of_existing_rows():
    index = truncation_row_index(50, torch.tensor([0.0, 0.1, 0.3, 0.5], dtype=torch.float64))
    assert index.shape == (4, 50)
    assert int(index.min()) >= 0 and int(index.max()) < 50
    torch.testing.assert_close(index[0], torch.arange(50))
    lost = [50 - len(set(row.tolist())) for row in index]
    assert lost == [0, 5, 15, 25]


@pytest.mark.parametrize(("level", "ratio"), [("weak", 0.1), ("medium", 0.2), ("strong", 0.3)])
def test_levels_map_to_paper_ratios(level, ratio):
    attack = EMTruncation(level)
    params = attack.sample_params(2, 64, 64)
    torch.testing.assert_close(params["ratio"], torch.full((2,), ratio))
    img = _random_uint8((3, 64, 48), seed=5)
    torch.testing.assert_close(attack(img), _chw(em_truncation_reference(_hwc(img), ratio)), atol=0, rtol=0)


def test_lost_rows_grow_with_intensity():
    attack = EMTruncation()
    s = torch.linspace(0, 1, 31)
    ratios = attack.ratio_for(s).double()
    lost = torch.floor(256 * ratios)
    assert lost[0] == 0 and (lost[1:] >= lost[:-1]).all() and lost[-1] == int(256 * 0.3)


def test_dtype_shape_layout_and_channels_preserved():
    attack = EMTruncation("strong")
    for img in (
        _random_uint8((3, 21, 13), 0),
        _random_uint8((2, 4, 21, 13), 1),
        _random_uint8((2, 2, 3, 21, 13), 2),
        torch.rand(1, 9, 9, generator=torch.Generator().manual_seed(0)),
        torch.rand(2, 3, 9, 9, dtype=torch.float64, generator=torch.Generator().manual_seed(0)),
        torch.zeros(3, 1, 1),
    ):
        out = attack(img)
        assert out.shape == img.shape and out.dtype == img.dtype and out.device == img.device
    gray = _random_uint8((1, 20, 5), 4)
    # channel-agnostic: a grey image is truncated exactly like each channel of an RGB image
    torch.testing.assert_close(attack(gray), em_truncation(gray.expand(3, -1, -1), 0.3)[:1], atol=0, rtol=0)


def test_intensity_zero_is_identity_and_random_intensity_varies_per_sample():
    img = _random_uint8((8, 3, 40, 40), 6)
    torch.testing.assert_close(EMTruncation(0.0)(img), img, atol=0, rtol=0)
    params = EMTruncation("random").sample_params(8, 40, 40, generator=torch.Generator().manual_seed(0))
    assert len(set(params["ratio"].tolist())) == 8
    assert ((params["ratio"] >= 0.1 - 1e-6) & (params["ratio"] <= 0.3 + 1e-6)).all()


def test_same_seed_same_output_and_pickle_round_trip():
    img = _random_uint8((4, 3, 30, 30), 7)
    a, b = EMTruncation("random", seed=3), EMTruncation("random", seed=3)
    torch.testing.assert_close(a(img), b(img), atol=0, rtol=0)
    clone = pickle.loads(pickle.dumps(a))
    torch.testing.assert_close(clone(img), a(img), atol=0, rtol=0)


def test_explicit_ratio_overrides_intensity():
    img = _random_uint8((3, 30, 30), 8)
    torch.testing.assert_close(EMTruncation("weak", ratio=0.4)(img), em_truncation(img, 0.4), atol=0, rtol=0)
    with pytest.raises(ValueError, match="ratio"):
        EMTruncation(ratio=0.7)


@pytest.mark.parametrize(
    ("ratio", "match"),
    [
        (-0.1, r"\[0, 0.5\]"),
        (float("nan"), r"\[0, 0.5\]"),
        (torch.tensor([0.1, 0.2]), "one value per sample"),
    ],
)
def test_bad_ratio_raises_clear_error(ratio, match):
    with pytest.raises(ValueError, match=match):
        em_truncation(_random_uint8((3, 3, 10, 10), 9), ratio)


def test_bad_images_raise():
    with pytest.raises(ValueError, match="shape"):
        em_truncation(torch.zeros(10, 10), 0.1)
    with pytest.raises(ValueError, match="channels"):
        em_truncation(torch.zeros(5, 10, 10), 0.1)
    with pytest.raises(ValueError, match="NaN"):
        em_truncation(torch.full((3, 4, 4), float("nan")), 0.1)


def test_full_hd_frame_keeps_shape_and_dtype():
    frame = _random_uint8((3, 1080, 1920), seed=12)
    out = EMTruncation("strong")(frame)
    assert out.shape == frame.shape and out.dtype == frame.dtype and not torch.equal(out, frame)


def test_random_draws_the_authors_uniform_ratio():
    """ "random" = the authors' training: ratio ~ U(0.1, 0.3)."""
    params = EMTruncation("random").sample_params(4000, 224, 224, generator=torch.Generator().manual_seed(0))
    ratio = params["ratio"].double()
    assert float(ratio.min()) >= 0.1 - 1e-6 and float(ratio.max()) <= 0.3 + 1e-6
    for quantile in (0.25, 0.5, 0.75):
        assert float((ratio < 0.1 + 0.2 * quantile).double().mean()) == pytest.approx(quantile, abs=0.03)


def test_one_shared_ratio_and_per_sample_ratios_take_the_same_rows():
    """The shared-ratio fast path (cached row index) equals the per-sample gather, for every dtype."""
    for img in (
        _random_uint8((3, 4, 29, 7), 9),
        torch.rand(3, 1, 29, 7, generator=torch.Generator().manual_seed(1)),
    ):
        shared = em_truncation(img, 0.3)
        per_sample = em_truncation(img, torch.tensor([0.3, 0.3, 0.0]))
        torch.testing.assert_close(per_sample[:2], shared[:2], atol=0, rtol=0)
        torch.testing.assert_close(per_sample[2], img[2], atol=0, rtol=0)
        assert shared.data_ptr() != img.data_ptr()


def test_calibrated_line_and_free_band_start_per_sample_anywhere_up_to_h_minus_num():
    """The calibrated options (issue 12): ``r = a s`` in place of the level table, and each sample's band start
    drawn over every row from the top to ``h - num`` (the tail itself included: that frame passes unchanged)."""
    height, batch = 40, 256
    attack = EMTruncation(0.8, ratio_per_intensity=0.25, free_band_position=True, seed=3)
    params = attack.sample_params(batch, height, 8, generator=torch.Generator().manual_seed(5))
    num = int(height * 0.25 * 0.8)  # 8 rows lost at every sample
    assert torch.allclose(params["ratio"], torch.full((batch,), 0.2))
    starts = torch.floor(params["start_fraction"] * (height - num + 1)).long()
    # every start from 0 to h - num is drawn, beyond the paper's clamp h - 2 num
    assert set(starts.tolist()) == set(range(height - num + 1))
    image = torch.arange(height, dtype=torch.float32).view(1, 1, height, 1).expand(batch, 3, height, 8)
    out = attack.apply_params(image, params)
    for k in range(batch):
        start = int(starts[k])
        rows = torch.arange(height)
        expected = torch.where((rows >= start) & (rows < height - num), rows + num, rows)
        assert torch.equal(out[k, 0, :, 0], expected.float()), start
    # at zero intensity nothing is lost, wherever the band would start
    zero = EMTruncation(0.0, ratio_per_intensity=0.25, free_band_position=True, seed=3)
    assert torch.equal(zero(image), image)

    # reproducible, picklable, and a generator is required
    def fresh():
        return EMTruncation(0.8, ratio_per_intensity=0.25, free_band_position=True, seed=3)

    clone = pickle.loads(pickle.dumps(fresh()))
    assert torch.equal(fresh()(image), clone(image))
    assert not torch.equal(fresh()(image), EMTruncation(0.8, free_band_position=True, seed=4)(image))
    with pytest.raises(ValueError, match=r"needs a torch\.Generator"):
        EMTruncation(0.8, free_band_position=True).sample_params(2, height, 8)
    with pytest.raises(ValueError, match=r"ratio_per_intensity must lie in \[0, 0.5\]"):
        EMTruncation(0.8, ratio_per_intensity=0.7)


def test_every_count_and_start_loses_the_rows_the_paper_deletes():
    """The row index (``rows_after_losing``, which the calibration's frame model predicts frames with too) against
    the reference's delete-and-append for every count, at the paper's clamped start and at every free start."""
    height = 24
    image = torch.arange(height, dtype=torch.float32).view(1, 1, height, 1).expand(1, 3, height, 2)
    column = _hwc(image[0])
    for num in range(height // 2 + 1):
        # inside [num, num + 1) rows, clear of float rounding (half the frame: exactly 0.5, the largest ratio)
        ratio = min(num + 0.5, height / 2) / height
        paper = em_truncation(image, torch.tensor([ratio]))[0]
        assert torch.equal(paper, _chw(em_truncation_reference(column, ratio))), num
        for start in range(height - num + 1):
            fraction = torch.tensor([(start + 0.5) / (height - num + 1)])
            free = em_truncation(image, torch.tensor([ratio]), fraction)[0]
            assert torch.equal(free, _chw(em_truncation_reference(column, ratio, start=start))), (num, start)


def _drawn_counts(attack: EMTruncation, height: int, intensity: torch.Tensor, seed: int) -> torch.Tensor:
    """Rows each sample loses: ``int(h r)`` of its drawn ratio, as ``em_truncation`` counts them."""
    params = attack.sample_params(
        len(intensity), height, 4, intensity=intensity, generator=torch.Generator().manual_seed(seed)
    )
    return torch.tensor([int(height * r) for r in params["ratio"].tolist()])


def test_a_spread_line_draws_the_counts_the_calibration_predicts_held_out_frames_with():
    """With the calibration's slope range (uniform slopes, counts consistent), its jitter (normal, counts that
    contradict one line) or both (counts that agree, and the jitter agreement leaves possible), each sample's count
    has the probability the calibration scores held-out frames with (``count_probabilities``), and every sample of a
    batch draws its own."""
    from lerobot_phantom.calibration.frame_models.em_truncation import count_probabilities

    height, draws, slope = 40, 20000, 0.25
    spread_line = EMTruncation(ratio_per_intensity=slope, ratio_per_intensity_spread=0.05)
    jittered_line = EMTruncation(ratio_per_intensity=slope, ratio_jitter=0.02)
    both = EMTruncation(ratio_per_intensity=slope, ratio_per_intensity_spread=0.05, ratio_jitter=0.02)
    for s in (0.3, 0.8, 1.0):
        counts = _drawn_counts(spread_line, height, torch.full((draws,), s), seed=int(s * 10))
        assert_frequencies_follow(
            counts.numpy(), *count_probabilities((slope - 0.05) * s, (slope + 0.05) * s, height, 20)
        )
        counts = _drawn_counts(jittered_line, height, torch.full((draws,), s), seed=int(s * 10) + 1)
        assert_frequencies_follow(
            counts.numpy(), *count_probabilities(slope * s, slope * s, height, 20, jitter=0.02)
        )
        counts = _drawn_counts(both, height, torch.full((draws,), s), seed=int(s * 10) + 2)
        law = count_probabilities((slope - 0.05) * s, (slope + 0.05) * s, height, 20, jitter=0.02)
        assert_frequencies_follow(counts.numpy(), *law)
        assert len(law[0]) > len(count_probabilities((slope - 0.05) * s, (slope + 0.05) * s, height, 20)[0])
    # without the spread and jitter the line gives one count per intensity
    assert set(
        _drawn_counts(EMTruncation(ratio_per_intensity=slope), height, torch.full((50,), 0.8), 0).tolist()
    ) == {8}


def test_equally_likely_jitters_draw_the_calibrations_mixture_and_keep_a_tuple():
    """The calibration writes its posterior's jitter quantiles (``ratio_jitter=[...]``): each sample draws one of
    them, so the counts follow the mixture the calibration predicts held-out frames with
    (``TruncationFrames.predicted_counts``), with tails no single jitter has."""
    from lerobot_phantom.calibration.core import Fit
    from lerobot_phantom.calibration.frame_models.common import Pair
    from lerobot_phantom.calibration.frame_models.em_truncation import TruncationFrames

    height, draws, jitters = 40, 20000, (0.005, 0.01, 0.04)
    attack = EMTruncation(
        ratio_per_intensity=0.25, ratio_per_intensity_spread=0.02, ratio_jitter=list(jitters)
    )
    assert attack.ratio_jitter == jitters
    # numpy's scalars are one jitter, as a float is; a numpy array is equally likely ones
    one = EMTruncation(ratio_per_intensity=0.25, ratio_jitter=np.float32(0.01)).ratio_jitter
    assert isinstance(one, float) and one == pytest.approx(0.01)
    assert EMTruncation(ratio_per_intensity=0.25, ratio_jitter=np.array(jitters)).ratio_jitter == jitters
    # a sequence of one jitter draws what that number draws (no draw of which jitter where there is no choice)
    one_and_a_sequence_of_one = [
        _drawn_counts(
            EMTruncation(ratio_per_intensity=0.25, ratio_jitter=j), height, torch.full((64,), 0.7), 4
        )
        for j in (0.02, [0.02])
    ]
    assert torch.equal(*one_and_a_sequence_of_one)
    blank = torch.zeros(3, height, 1)
    for s in (0.3, 1.0):
        problem = TruncationFrames([Pair("frame", blank, blank, None, s)], 0)
        fit = Fit(frozenset(), {}, {"slope_range": [0.23, 0.27], "jitters": list(jitters)})
        law = problem.predicted_counts(fit, 0)
        counts = _drawn_counts(attack, height, torch.full((draws,), s), seed=int(s * 10) + 5)
        assert_frequencies_follow(counts.numpy(), *law)
        middle = EMTruncation(ratio_per_intensity=0.25, ratio_per_intensity_spread=0.02, ratio_jitter=0.01)
        assert np.ptp(counts.numpy()) > np.ptp(
            _drawn_counts(middle, height, torch.full((draws,), s), 1).numpy()
        )
    image = torch.rand(4, 3, height, 8, generator=torch.Generator().manual_seed(0))

    def fresh():
        return EMTruncation(0.9, ratio_per_intensity=0.25, ratio_jitter=jitters, seed=3)

    assert torch.equal(pickle.loads(pickle.dumps(fresh()))(image), fresh()(image))
    assert "ratio_jitter=(0.005, 0.01, 0.04)" in repr(fresh())


def test_a_spread_line_loses_each_samples_drawn_rows_and_none_at_zero_intensity():
    height, batch = 40, 64
    image = torch.arange(height, dtype=torch.float32).view(1, 1, height, 1).expand(batch, 3, height, 2)
    attack = EMTruncation(
        0.9, ratio_per_intensity=0.3, ratio_per_intensity_spread=0.1, ratio_jitter=0.05, seed=7
    )
    params = attack.sample_params(batch, height, 2, generator=torch.Generator().manual_seed(1))
    assert len(set(params["ratio"].tolist())) > batch // 2  # per sample, not one draw for the batch
    assert bool(((params["ratio"] >= 0) & (params["ratio"] <= 0.5)).all())
    out = attack.apply_params(image, params)
    for k in range(batch):
        expected = em_truncation_reference(_hwc(image[k]), float(params["ratio"][k]))
        assert torch.equal(out[k], _chw(expected)), k
    # jitter is the attack's spread, not an attack of its own: at zero intensity every frame passes unchanged
    zero = EMTruncation(
        0.0, ratio_per_intensity=0.3, ratio_per_intensity_spread=0.1, ratio_jitter=0.05, seed=7
    )
    assert torch.equal(zero(image), image)
    mixed = torch.tensor([0.0, 0.5, 1.0]).repeat(20)
    counts = _drawn_counts(attack, height, mixed, seed=2)
    assert (counts[mixed == 0] == 0).all() and (counts[mixed > 0] > 0).any()

    def fresh():
        return EMTruncation(
            0.9, ratio_per_intensity=0.3, ratio_per_intensity_spread=0.1, ratio_jitter=0.05, seed=7
        )

    assert torch.equal(pickle.loads(pickle.dumps(fresh()))(image), fresh()(image))
    assert "ratio_jitter=0.05" in repr(fresh())


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"ratio_per_intensity_spread": 0.05}, "they need ratio_per_intensity"),
        (
            {"ratio_per_intensity": 0.1, "ratio_per_intensity_spread": 0.2},
            r"must not exceed ratio_per_intensity",
        ),
        ({"ratio_per_intensity": 0.1, "ratio_jitter": 0.6}, r"ratio_jitter must lie in \[0, 0.5\]"),
        ({"ratio_per_intensity": 0.1, "ratio_jitter": [0.01, 0.6]}, r"ratio_jitter must lie in \[0, 0.5\]"),
        ({"ratio_per_intensity": 0.1, "ratio_jitter": []}, "a number or a non-empty sequence"),
        ({"ratio_per_intensity": 0.1, "ratio_per_intensity_spread": -0.01}, r"spread must lie in \[0, 0.5\]"),
    ],
)
def test_a_spread_line_refuses_options_that_describe_no_law(options, message):
    with pytest.raises(ValueError, match=message):
        EMTruncation(0.5, **options)


def test_a_spread_line_needs_a_generator():
    attack = EMTruncation(0.5, ratio_per_intensity=0.2, ratio_jitter=0.01)
    with pytest.raises(ValueError, match=r"ratio_jitter need a torch\.Generator"):
        attack.sample_params(2, 40, 8)


def test_a_fixed_ratio_wins_over_a_calibrated_spread_line():
    """``make_attack(..., calibration=DIR, ratio=0.2)``: the explicit ratio, as it wins over the measured line."""
    attack = EMTruncation(
        0.7, ratio=0.2, ratio_per_intensity=0.3, ratio_per_intensity_spread=0.1, ratio_jitter=0.05
    )
    params = attack.sample_params(16, 40, 8, generator=torch.Generator().manual_seed(0))
    assert torch.allclose(params["ratio"], torch.full((16,), 0.2))
