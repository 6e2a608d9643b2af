"""Property tests shared by every camera attack of the registry (hypothesis)."""

import os
import pickle

import pytest
import torch
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from lerobot_phantom.transforms.registry import CAMERA_ATTACKS, get_attack_class, make_attack

os.environ.setdefault("HF_HUB_OFFLINE", "1")

# derandomize: the same examples on every run (CI never flakes); database=None: nothing written to the repo
PROPERTY_SETTINGS = settings(
    max_examples=15,
    deadline=None,
    derandomize=True,
    database=None,
    suppress_health_check=[HealthCheck.too_slow],
)

# Where "mean absolute difference to the clean image grows with s" does not hold for the paper's algorithm itself
# (documented in each attack's docstring), the property is checked on the range where it does hold, or not at all.
MONOTONE_UP_TO = {
    # the three levels each corrupt about half of the rows: only the weak ramp (band thickness 0 -> 1) is monotone
    "em_color_strip": 1.0 / 3.0,
    # a band of int(h r) rows is lost, but the rows that change ([start, h - num)) shrink as r grows
    "em_truncation": 0.0,
}


def _image(shape, dtype, seed):
    generator = torch.Generator().manual_seed(seed)
    if dtype == torch.uint8:
        return torch.randint(0, 256, shape, dtype=torch.uint8, generator=generator)
    return torch.rand(shape, generator=generator).to(dtype)


@st.composite
def images(draw, min_side=1, max_side=40):
    dtype = draw(st.sampled_from([torch.uint8, torch.float32, torch.float64]))
    leading = draw(st.sampled_from([(), (1,), (3,), (2, 2)]))
    channels = draw(st.sampled_from([1, 3, 4]))
    height = draw(st.integers(min_side, max_side))
    width = draw(st.integers(min_side, max_side))
    return _image((*leading, channels, height, width), dtype, draw(st.integers(0, 2**16)))


def _smooth_image(shape, seed):
    """A camera-like frame: a random low-resolution field upsampled (smooth), values in [0, 1]."""
    coarse = torch.rand(1, shape[0], 4, 4, generator=torch.Generator().manual_seed(seed))
    return torch.nn.functional.interpolate(coarse, size=shape[1:], mode="bilinear", align_corners=True)[0]


def _distortion(attack, image, s, seed):
    params = attack.sample_params(
        1, *image.shape[-2:], intensity=torch.tensor([s]), generator=torch.Generator().manual_seed(seed)
    )
    return float((attack.apply_params(image, params).double() - image.double()).abs().mean())


@pytest.mark.parametrize("name", CAMERA_ATTACKS)
@PROPERTY_SETTINGS
@given(image=images(), s=st.floats(0.0, 1.0), seed=st.integers(0, 1000))
def test_dtype_shape_device_and_range_are_preserved(name, image, s, seed):
    out = make_attack(name, intensity=s, seed=seed)(image)
    assert out.shape == image.shape and out.dtype == image.dtype and out.device == image.device
    if out.is_floating_point():
        assert bool(torch.isfinite(out).all()) and float(out.min()) >= 0.0 and float(out.max()) <= 1.0


@pytest.mark.parametrize("name", CAMERA_ATTACKS)
@PROPERTY_SETTINGS
@given(image=images(), seed=st.integers(0, 1000))
def test_intensity_zero_is_identity(name, image, seed):
    out = make_attack(name, intensity=0.0, seed=seed)(image)
    if image.dtype == torch.uint8:
        assert torch.equal(out, image)
    else:
        assert torch.allclose(out, image, atol=1e-6, rtol=0)


@pytest.mark.parametrize("name", CAMERA_ATTACKS)
@PROPERTY_SETTINGS
@given(
    size=st.tuples(st.integers(8, 40), st.integers(8, 40)),
    image_seed=st.integers(0, 2**16),
    s=st.lists(st.floats(0.0, 1.0), min_size=2, max_size=2, unique=True),
    seed=st.integers(0, 1000),
)
def test_distortion_is_monotone_in_intensity(name, size, image_seed, s, seed):
    upper = MONOTONE_UP_TO.get(name, 1.0)
    if upper == 0.0:
        pytest.skip(
            f"{name}: distortion is not monotone in intensity for the paper's algorithm (see its docstring)"
        )
    image = _smooth_image((3, *size), image_seed)
    attack = make_attack(name, intensity="medium", seed=seed)
    low, high = sorted(v * upper for v in s)
    assert _distortion(attack, image, low, seed) <= _distortion(attack, image, high, seed) + 1e-5


@pytest.mark.parametrize("name", CAMERA_ATTACKS)
def test_strong_distorts_more_than_weak_more_than_clean(name):
    # a smooth, camera-like frame (noise would favour attacks that move rows by one pixel)
    rows = torch.linspace(0, 1, 48)[:, None]
    cols = torch.linspace(0, 1, 64)[None, :]
    image = torch.stack([rows * cols, (1 - rows) * 0.8 + 0.1 * cols, 0.5 + 0.4 * torch.sin(6 * cols) * rows])
    attack = make_attack(name, intensity="medium", seed=0)
    clean, weak, strong = (_distortion(attack, image, s, 0) for s in (0.0, 1 / 3, 1.0))
    assert clean == 0.0 < weak and strong > 0.0
    if MONOTONE_UP_TO.get(name, 1.0) == 1.0:
        assert weak < strong


@pytest.mark.parametrize("name", CAMERA_ATTACKS)
@PROPERTY_SETTINGS
@given(image=images(min_side=4), seed=st.integers(0, 2**31))
def test_same_seed_gives_identical_output(name, image, seed):
    first = make_attack(name, intensity="random", seed=seed)
    second = make_attack(name, intensity="random", seed=seed)
    assert torch.equal(first(image), second(image))
    assert torch.equal(first(image), second(image))  # and the streams stay in step


@pytest.mark.parametrize("name", CAMERA_ATTACKS)
def test_samples_in_a_batch_get_different_random_parameters(name):
    image = _image((3, 32, 40), torch.float32, 2)
    batch = image.expand(8, -1, -1, -1).clone()
    attack = make_attack(name, intensity="random", seed=7)
    params = attack.sample_params(8, 32, 40, generator=torch.Generator().manual_seed(3))
    assert params["intensity"].shape == (8,)
    # integer-valued physical parameters ("random" = the authors' randint draws, e.g. 9 stripe counts) repeat in
    # a batch of 8, continuous ones do not; either way a batch must not share one draw
    distinct_intensities = len(set(params["intensity"].tolist()))
    integer_valued = get_attack_class(name).random_parameter.integer
    assert distinct_intensities >= (4 if integer_valued else 8)
    out = attack(batch)
    distinct = {tuple(o.flatten()[::37].tolist()) for o in out}
    assert len(distinct) > 1


@pytest.mark.parametrize("name", CAMERA_ATTACKS)
def test_params_with_leading_dim_one_broadcast_over_the_batch(name):
    batch = _image((4, 3, 20, 24), torch.uint8, 4)
    attack = make_attack(name, intensity="random", seed=1)
    params = attack.sample_params(1, 20, 24, generator=torch.Generator().manual_seed(0))
    out = attack.apply_params(batch, params)
    for i in range(4):
        assert torch.equal(out[i], attack.apply_params(batch[i], params))


@pytest.mark.parametrize("name", CAMERA_ATTACKS)
def test_pickling_round_trips(name):
    image = _image((2, 3, 20, 30), torch.uint8, 5)
    attack = make_attack(name, intensity="random", seed=11)
    attack(image)  # advance the generator and fill any caches
    clone = pickle.loads(pickle.dumps(attack))
    assert type(clone) is type(attack)
    assert torch.equal(clone(image), attack(image))


@pytest.mark.skipif(not torch.cuda.is_available(), reason="no CUDA device")
@pytest.mark.parametrize("name", CAMERA_ATTACKS)
def test_cuda_matches_cpu(name):
    image = _image((2, 3, 33, 47), torch.uint8, 6)
    attack = make_attack(name, intensity="strong", seed=0)
    params = attack.sample_params(2, 33, 47, generator=torch.Generator().manual_seed(0))
    cpu = attack.apply_params(image, params)
    gpu = attack.apply_params(image.cuda(), {k: v.cuda() for k, v in params.items()})
    assert gpu.device.type == "cuda" and gpu.dtype == image.dtype
    assert (gpu.cpu().int() - cpu.int()).abs().max() <= 1
