"""EM color strip: electromagnetic interference on the camera bus breaks colour decoding in horizontal bands (paper,
Method and Appendix A, Algorithm "EM Color Strip Attack"; after GlitchHiker, Jiang et al. 2023).

The paper's algorithm, for ``N`` stripes on an image of height ``h`` (pixel values 0-255)::

    step = int(h / N)
    for down in range(0, h - step, 2 * step):          # every other band of `step` rows
        rows [down, down + step):  R' = clip(int(2.5 G)),  G' = clip(int((R + B) / 2) - 50),  B' = clip(int(2.5 G))

with every new value computed from the pixel's original R, G, B. Levels: N = 8 / 12 / 16 at weak / medium / strong
(Table 2).

Deviations from the paper's code (and why):

* **No uint8 overflow.** The released code adds R and B as ``np.uint8``, which wraps modulo 256, so a bright
  pixel (R + B > 255) gets a *dark* green channel. Here the sum is computed in float: the paper's formula as
  written.
* **Continuous values for float images** (``2.5 G`` instead of ``int(2.5 G)``). uint8 images are computed in
  integers with the paper's truncating ``int()`` exactly (no float round trip), so the two paths are within one
  grey level of each other.
* **At least one row per band.** ``step = max(1, int(h / N))``: the released code crashes (``range`` step 0) on
  images with fewer rows than stripes.
* **Continuous intensity** (the paper has only three levels). With ``s`` the intensity (weak = 1/3, medium = 2/3,
  strong = 1):

  - ``0 <= s <= 1/3``: the weak pattern (N = 8) with every band thinned to ``band_fraction = 3 s`` of its height
    (the partial row is blended), so ``s = 0`` is the identity and the corrupted rows only grow with ``s``.
  - ``1/3 <= s <= 2/3`` and ``2/3 <= s <= 1``: the patterns of the two neighbouring levels (8 -> 12 and
    12 -> 16 stripes) are cross-faded per row with weight ``mix = 3 s - 1`` resp. ``3 s - 2``. Interpolating ``N``
    itself would not do: the corrupted area of the paper's pattern jumps around for non-level ``N`` (for h = 256:
    128 rows at N = 8, 112 at N = 9, 138 at N = 11, 126 at N = 12, 128 at N = 16), whereas the cross-fade moves the
    mean absolute difference to the clean image linearly from one level's value to the next.

  The three levels are the paper's patterns exactly. Between levels the distortion is monotone whenever the
  paper's own levels are ordered for the image; they cover about half of the frame each (for h = 256:
  128 / 126 / 128 rows), so for a given image the medium level can distort slightly less than the weak one.
* **Memory-bound**: the band pattern is a per-row weight. When every sample shares it (a level, a fixed
  ``num_stripes``) the bands are corrupted in place through strided views of a copy of the batch (the periodic
  bands are one view); per-sample patterns (``"random"``, intensity ranges) gather the corrupted rows of the whole
  batch, corrupt them, and gather the output back (no per-sample loop; a row scatter is several times slower).
* **"random"** draws the authors' adversarial-training stripe count ``N = randint(8, 16)`` and applies the paper's
  pattern for that ``N`` (a per-sample intensity tensor, e.g. the mixer's, still means the continuous map above).
"""

from __future__ import annotations

import functools
from typing import ClassVar

import torch

from lerobot_phantom.transforms import physics
from lerobot_phantom.transforms.base import (
    CameraAttack,
    check_image,
    from_float_rgb,
    from_uint8_rgb,
    per_sample_values,
    to_float_rgb,
    to_rgb,
)
from lerobot_phantom.transforms.intensity import (
    IntensitySpec,
    RandomParameter,
    interpolate_levels,
    is_random,
)

LEVEL_STRIPES: tuple[float, float, float] = (8.0, 12.0, 16.0)
STRIPE_LEVEL_MAP: tuple[float, float, float, float] = (LEVEL_STRIPES[0], *LEVEL_STRIPES)
"""Stripes at s = 0, weak, medium, strong for ``"random"``'s inverse map (below weak the bands thin instead)."""
FLOAT_CHUNK_BYTES = 2 << 20
"""Float batches are corrupted a few images (about this many bytes) at a time, in cache."""
GREEN_GAIN = 2.5
GREEN_OFFSET = 50.0 / 255.0


def stripe_row_weights(height: int, num_stripes: torch.Tensor, band_fraction: torch.Tensor) -> torch.Tensor:
    """Per-row corruption weight in [0, 1], ``(B, height)``, for per-sample stripe counts and band fractions."""
    step = torch.clamp(torch.floor(height / num_stripes), min=1.0).unsqueeze(1)  # (B, 1)
    rows = torch.arange(height, device=num_stripes.device, dtype=torch.float64).unsqueeze(0)  # (1, H)
    band = torch.floor(rows / step)
    band_start = band * step
    covered = (torch.remainder(band, 2) == 0) & (band_start < height - step)
    thickness = band_fraction.unsqueeze(1) * step - (rows - band_start)
    return torch.where(covered, thickness.clamp(0.0, 1.0), torch.zeros_like(thickness))


def em_color_error(x: torch.Tensor) -> torch.Tensor:
    """The colour-decoding error on float RGB ``(B, 3, H, W)`` in [0, 1] (every pixel, from the original values)."""
    out = x.clone()
    _corrupt_(out)
    return out


def _corrupt_(view: torch.Tensor, dim: int = 1) -> None:
    """Overwrite the RGB planes of ``view`` (the three channels along ``dim``) with the colour error, in place.

    uint8 computes the paper's integer formula exactly: ``int(2.5 G)`` = ``2 G + G // 2`` (255 from G = 102 on) and
    ``int((R + B) / 2)`` = ``(R & B) + ((R ^ B) >> 1)`` (no uint8 wrap-around), minus 50 saturating at 0. Float keeps
    continuous values. Both are within one grey level of each other. R and B get the same value, written by one op
    through the view of both planes (10 uint8 ops, 4 float ops: every op counts on small views).
    """
    red, green, blue = view.unbind(dim)
    red_and_blue = view[(slice(None),) * dim + (slice(None, None, 2),)]
    if view.dtype == torch.uint8:
        new_green = torch.bitwise_and(red, blue)
        new_green.add_(torch.bitwise_xor(red, blue).bitwise_right_shift_(1)).clamp_(min=50).sub_(50)
        capped = green.clamp(max=102)
        half = capped.bitwise_right_shift(1)
        both = red_and_blue.shape
        torch.add(
            half.unsqueeze(dim).expand(both), capped.unsqueeze(dim).expand(both), alpha=2, out=red_and_blue
        )
        green.copy_(new_green)
    else:
        # one clamp for the three planes at the end: clamp(2.5 G) for R and B, clamp((R + B) / 2 - offset) for G
        average = torch.lerp(red, blue, 0.5)
        torch.mul(green.unsqueeze(dim).expand(red_and_blue.shape), GREEN_GAIN, out=red_and_blue)
        torch.sub(average, GREEN_OFFSET, out=green)
        view.clamp_(0.0, 1.0)


def _check_stripes(num_stripes: torch.Tensor) -> None:
    if not torch.isfinite(num_stripes).all() or (num_stripes < 1).any():
        raise ValueError(f"num_stripes must be >= 1, got {num_stripes.tolist()}")


def _row_weights(
    height: int,
    batch: int,
    device: torch.device,
    num_stripes: float | torch.Tensor,
    band_fraction: float | torch.Tensor,
    next_num_stripes: float | torch.Tensor | None,
    mix: float | torch.Tensor,
) -> torch.Tensor:
    """Validated parameters -> per-row corruption weights ``(batch, height)`` float64."""
    stripes = per_sample_values(num_stripes, batch, device, "num_stripes")
    fraction = per_sample_values(band_fraction, batch, device, "band_fraction")
    _check_stripes(stripes)
    if not ((fraction >= 0) & (fraction <= 1)).all():
        raise ValueError(f"band_fraction must lie in [0, 1], got {fraction.tolist()}")
    weights = stripe_row_weights(height, stripes, fraction)
    if next_num_stripes is not None:
        following = per_sample_values(next_num_stripes, batch, device, "next_num_stripes")
        _check_stripes(following)
        weight_of_next = per_sample_values(mix, batch, device, "mix")
        if not ((weight_of_next >= 0) & (weight_of_next <= 1)).all():
            raise ValueError(f"mix must lie in [0, 1], got {weight_of_next.tolist()}")
        if bool((weight_of_next > 0).any()):
            weight_of_next = weight_of_next.unsqueeze(1)
            weights = (1 - weight_of_next) * weights + weight_of_next * stripe_row_weights(
                height, following, fraction
            )
    return weights


def row_weights_of(x: torch.Tensor, params: dict[str, torch.Tensor]) -> torch.Tensor:
    """Per-row corruption weights ``(batch, height)`` of the paper's bands for the transform's ``params`` on ``x``."""
    keys = ("num_stripes", "band_fraction", "next_num_stripes", "mix")
    return _row_weights(x.shape[-2], x.shape[0], x.device, *(params[k] for k in keys))


def _runs(row_weights: list[float]) -> list[tuple[int, int]]:
    """``[start, stop)`` runs of fully corrupted rows."""
    runs, start = [], None
    for row, weight in enumerate([*row_weights, 0.0]):
        if weight == 1.0 and start is None:
            start = row
        elif weight != 1.0 and start is not None:
            runs.append((start, row))
            start = None
    return runs


def _corrupt_bands_(out: torch.Tensor, runs: list[tuple[int, int]]) -> None:
    """Corrupt the same rows of every image of ``out`` in place, through views (no gather, no scatter).

    The paper's bands are periodic (``step`` rows every ``2 step``), so all of them are one strided view: a handful
    of ops whatever the stripe count.
    """
    periodic = len(runs) >= 2 and all(
        b - a == runs[0][1] - runs[0][0] and a == runs[0][0] + k * (runs[1][0] - runs[0][0])
        for k, (a, b) in enumerate(runs)
    )
    if periodic:
        # every band in one view, the last one included although its period would run past the frame
        first, period, length = runs[0][0], runs[1][0] - runs[0][0], runs[0][1] - runs[0][0]
        s_image, s_channel, s_row, s_col = out.stride()
        views = [
            out.as_strided(
                (out.shape[0], 3, len(runs), length, out.shape[3]),
                (s_image, s_channel, period * s_row, s_row, s_col),
                out.storage_offset() + first * s_row,
            )
        ]
    else:
        views = [out[:, :, a:b] for a, b in runs]
    for view in views:
        _corrupt_(view)


def _corrupt_rows_gathered(out: torch.Tensor, weights: torch.Tensor) -> torch.Tensor:
    """Per-sample patterns and partial rows: gather the corrupted rows, corrupt them, gather the output back.

    Scatters (``index_copy_``, ``index_put_``) are several times slower than a row gather on the CPU, so the output
    is one gather from [image rows; corrupted rows].
    """
    batch, _, height, width = out.shape
    sample, row = (weights > 0).nonzero().unbind(1)
    first = sample * (3 * height) + row
    index = torch.cat([first, first + height, first + 2 * height])  # the R, G, B rows of every corrupted row
    count = out.numel() // width
    rows = out.view(count, width)
    source = torch.empty((count + index.numel(), width), dtype=out.dtype, device=out.device)
    source[:count].copy_(rows)
    corrupted = source[count:].view(3, -1, width)
    torch.index_select(rows, 0, index, out=source[count:])
    weight = weights[sample, row]
    partial = (weight < 1).nonzero().squeeze(1)
    original = corrupted.index_select(1, partial) if partial.numel() else None
    _corrupt_(corrupted, dim=0)
    if original is not None:
        w = weight.index_select(0, partial).to(torch.float32)[None, :, None]
        if out.dtype == torch.uint8:  # the partial rows' blend in float, on those rows only
            clean = original.to(torch.float32).div_(255.0)
            blended = torch.lerp(clean, em_color_error(clean[None])[0], w).mul_(255.0).round_()
            corrupted[:, partial] = blended.to(torch.int16).to(torch.uint8)  # 3x faster than float -> uint8
        else:
            corrupted[:, partial] = torch.lerp(original, corrupted.index_select(1, partial), w.to(out.dtype))
    source_of = torch.arange(count, device=out.device)
    source_of[index] = torch.arange(count, count + index.numel(), device=out.device)
    return source.index_select(0, source_of).view(batch, 3, height, width)


@functools.lru_cache(maxsize=256)
def _band_runs(
    height: int, num_stripes: float, band_fraction: float, next_num_stripes: float, mix: float
) -> tuple[tuple[int, int], ...] | None:
    """The fully corrupted row runs of one parameter set, or None when it has partial rows (validated; pure, so
    cached: a level or the 9 stripe counts of ``"random"`` cost no tensor op per call)."""
    weights = _row_weights(height, 1, torch.device("cpu"), num_stripes, band_fraction, next_num_stripes, mix)[
        0
    ]
    if not bool(((weights == 0) | (weights == 1)).all()):
        return None
    return tuple(_runs(weights.tolist()))


def _values(value: float | torch.Tensor, batch: int, what: str) -> list[float]:
    """A scalar or a ``(batch,)`` / ``(1,)`` tensor -> ``batch`` Python floats (one host copy, no tensor ops)."""
    values = value.reshape(-1).tolist() if isinstance(value, torch.Tensor) else [float(value)]
    if len(values) == 1:
        return values * batch
    if len(values) != batch:
        raise ValueError(
            f"{what} must be a scalar or have one value per sample ({batch}), got {len(values)} values"
        )
    return [float(v) for v in values]


def _consecutive(members: list[int]) -> list[tuple[int, int]]:
    """Increasing indices -> ``[first, stop)`` runs of consecutive ones."""
    runs: list[tuple[int, int]] = []
    for i in members:
        if runs and runs[-1][1] == i:
            runs[-1] = (runs[-1][0], i + 1)
        else:
            runs.append((i, i + 1))
    return runs


def em_color_strip_rgb(
    x: torch.Tensor,
    num_stripes: float | torch.Tensor,
    band_fraction: float | torch.Tensor = 1.0,
    next_num_stripes: float | torch.Tensor | None = None,
    mix: float | torch.Tensor = 0.0,
) -> torch.Tensor:
    """``em_color_strip`` on RGB ``(B, 3, H, W)``, uint8 or float (the transform's inner op).

    Returns a fresh tensor; float values are clamped to [0, 1] (the input first, so every output row is too).
    Samples with whole-row patterns (the levels, ``"random"``'s integer stripe counts) are grouped by pattern and
    corrupted in place through strided views: uint8 batches are copied once in group order and once back (two
    cheap copies instead of ~20 ops per sample), float batches per run of consecutive samples of a copy; other
    patterns gather their rows.
    """
    batch, _, height, _ = x.shape
    columns = [
        _values(value, batch, what)
        for value, what in (
            (num_stripes, "num_stripes"),
            (band_fraction, "band_fraction"),
            (num_stripes if next_num_stripes is None else next_num_stripes, "next_num_stripes"),
            (mix, "mix"),
        )
    ]
    groups: dict[tuple[tuple[int, int], ...], list[int]] = {}
    for i, key in enumerate(zip(*columns, strict=True)):
        runs = _band_runs(height, *key)
        if runs is None:
            groups = {}
            break
        groups.setdefault(runs, []).append(i)
    if groups:
        if x.dtype != torch.uint8:
            # float: each run of consecutive samples with one pattern is clamped into the output and corrupted
            # there a few images at a time, while they are in cache (a grouping copy of the batch would cost more)
            out = torch.empty(x.shape, dtype=x.dtype, device=x.device)
            per_chunk = max(1, FLOAT_CHUNK_BYTES // (x[0].numel() * x.element_size()))
            for runs, members in groups.items():
                for first, stop in _consecutive(members):
                    for start in range(first, stop, per_chunk):
                        chunk = slice(start, min(stop, start + per_chunk))
                        torch.clamp(x[chunk], 0.0, 1.0, out=out[chunk])
                        _corrupt_bands_(out[chunk], list(runs))
            return out
        if len(groups) == 1:
            out = x.clone().contiguous()
            _corrupt_bands_(out, list(next(iter(groups))))
            return out
        order = [i for members in groups.values() for i in members]
        index = torch.tensor(order, device=x.device)
        grouped = x.index_select(0, index)  # whole images: a memcpy each, unlike a row gather
        first = 0
        for runs, members in groups.items():
            _corrupt_bands_(grouped[first : first + len(members)], list(runs))
            first += len(members)
        return grouped.index_select(0, torch.argsort(index))
    weights = _row_weights(height, batch, x.device, num_stripes, band_fraction, next_num_stripes, mix)
    out = (x.clone() if x.dtype == torch.uint8 else x.clamp(0.0, 1.0)).contiguous()
    if not bool((weights > 0).any()):
        return out
    return _corrupt_rows_gathered(out, weights)


def em_color_strip(
    image: torch.Tensor,
    num_stripes: float | torch.Tensor,
    band_fraction: float | torch.Tensor = 1.0,
    next_num_stripes: float | torch.Tensor | None = None,
    mix: float | torch.Tensor = 0.0,
) -> torch.Tensor:
    """EM color strip of ``image`` (uint8 or float [0, 1], ``(..., C, H, W)``, C in {1, 3, 4}).

    ``num_stripes`` (N >= 1) is the paper's parameter; ``band_fraction`` in [0, 1] thins every corrupted band;
    ``next_num_stripes`` with ``mix`` in [0, 1] cross-fades to a second pattern (used between the paper's levels).
    Each may be a float or one value per image. Returns the input's shape, dtype and device. uint8 images are
    computed in integers (the paper's ``int()`` formula), float images in float.
    """
    check_image(image)
    if image.dtype == torch.uint8:
        x, alpha = to_rgb(image)
        return from_uint8_rgb(
            em_color_strip_rgb(x, num_stripes, band_fraction, next_num_stripes, mix), alpha, image
        )
    x, alpha = to_float_rgb(image)
    y = em_color_strip_rgb(x, num_stripes, band_fraction, next_num_stripes, mix)
    return from_float_rgb(y, alpha, image, in_unit_range=True)


def stripe_params_for(s: torch.Tensor) -> dict[str, torch.Tensor]:
    """Intensity ``s`` (per sample) -> the kernel's parameters (see the module docstring)."""
    levels = torch.tensor((LEVEL_STRIPES[0], *LEVEL_STRIPES), dtype=torch.float32, device=s.device)
    pos = s.to(torch.float32).clamp(0.0, 1.0) * 3.0
    segment = (
        pos.floor().clamp(max=2).long()
    )  # 0: thinning weak bands, 1: weak -> medium, 2: medium -> strong
    frac = pos - segment.to(torch.float32)
    thinning = segment == 0
    return {
        "num_stripes": levels[segment],
        "next_num_stripes": levels[segment + 1],
        "mix": torch.where(thinning, torch.zeros_like(frac), frac),
        "band_fraction": torch.where(thinning, frac, torch.ones_like(frac)),
    }


class EMColorStrip(CameraAttack):
    """EM color strip attack as a torchvision v2 transform.

    Intensity -> stripes: identity / 8 (weak) / 12 (medium) / 16 (strong), paper Table 2; see the module docstring
    for the continuous mapping. ``num_stripes=`` fixes the paper's stripe count whatever the intensity. ``gain`` and
    ``offset`` (a camera's measured colour map, ``physics.em_color_map``; the paper's 2.5 and 50 / 255 by default)
    colour the mis-decoded rows in either model.
    """

    name: ClassVar[str] = "em_color_strip"
    _apply_in_unit_range: ClassVar[bool] = True
    LEVEL_STRIPES: ClassVar[tuple[float, float, float]] = LEVEL_STRIPES
    # the authors' adversarial training: N = randint(8, 16) stripes (both ends included)
    random_parameter: ClassVar[RandomParameter] = RandomParameter(
        8, 16, integer=True, levels=STRIPE_LEVEL_MAP
    )

    def __init__(
        self,
        intensity: IntensitySpec = "medium",
        *,
        num_stripes: int | None = None,
        model: str = "paper",
        gain: float = GREEN_GAIN,
        offset: float = GREEN_OFFSET,
        max_fraction: float = 0.75,
        demosaic_pattern: str | None = None,
        seed: int | None = None,
        generator: torch.Generator | None = None,
    ) -> None:
        super().__init__(intensity, seed=seed, generator=generator)
        # model="bayer_phase_flip" (lerobot-phantom-calibrate): the wrong colours run from a row to the frame's
        # end; the flipped share of rows grows with the intensity up to max_fraction
        if model not in ("paper", "bayer_phase_flip"):
            raise ValueError(f"unknown EM color strip model {model!r}; valid: 'paper', 'bayer_phase_flip'")
        if not (0.0 < max_fraction <= 1.0):
            raise ValueError(f"max_fraction must lie in (0, 1], got {max_fraction!r}")
        # demosaic_pattern (a colour-filter tile, lerobot-phantom-calibrate's bayer_demosaic): mis-decoded rows are
        # the demosaic after a lost line with the map's gain and offset, in either model, instead of the map of
        # each pixel
        if demosaic_pattern is not None and demosaic_pattern not in physics.BAYER_PATTERNS:
            raise ValueError(
                f"unknown demosaic_pattern {demosaic_pattern!r}; valid: None, {', '.join(physics.BAYER_PATTERNS)}"
            )
        self.demosaic_pattern = demosaic_pattern
        self.model = model
        self.bayer = {"gain": float(gain), "offset": float(offset), "max_fraction": float(max_fraction)}
        if num_stripes is not None and int(num_stripes) < 1:
            raise ValueError(f"num_stripes must be >= 1, got {num_stripes!r}")
        self.num_stripes = None if num_stripes is None else int(num_stripes)

    def sample_params(
        self,
        batch_size: int,
        height: int,
        width: int,
        *,
        intensity: IntensitySpec | torch.Tensor | None = None,
        generator: torch.Generator | None = None,
        device: torch.device | str | None = None,
    ) -> dict[str, torch.Tensor]:
        """As ``CameraAttack.sample_params``; ``"random"`` gives the paper's pattern for the drawn integer N (the
        authors' training), not the cross-fade of the neighbouring levels that the same ``s`` means elsewhere."""
        drawn = is_random(self.intensity if intensity is None else intensity)
        if not (drawn and self.model == "paper" and self.num_stripes is None):
            return super().sample_params(
                batch_size, height, width, intensity=intensity, generator=generator, device=device
            )
        # the same draw as the base's, without _sample's cross-fade parameters (replaced here: ~10 ops per call)
        s = self._intensities(batch_size, intensity, generator, device)
        stripes = interpolate_levels(s, STRIPE_LEVEL_MAP).round()
        ones = torch.ones_like(stripes)
        return {
            "num_stripes": stripes,
            "next_num_stripes": stripes,
            "mix": 0 * ones,
            "band_fraction": ones,
            "intensity": s,
        }

    def _sample(self, s, height, width, generator, device):
        if self.model == "bayer_phase_flip":
            return {"start_fraction": (1.0 - self.bayer["max_fraction"] * s.to(torch.float32)).to(device)}
        if self.num_stripes is not None:
            fixed = torch.full_like(s, float(self.num_stripes), dtype=torch.float32)
            ones = torch.ones_like(fixed)
            return {"num_stripes": fixed, "next_num_stripes": fixed, "mix": 0 * ones, "band_fraction": ones}
        return {k: v.to(device) for k, v in stripe_params_for(s).items()}

    def _apply(self, x: torch.Tensor, params: dict[str, torch.Tensor]) -> torch.Tensor:
        if self.model == "bayer_phase_flip":
            height = x.shape[-2]
            rows = physics.bayer_flip_mask(
                height, params["start_fraction"].to(x.device) * height, device=x.device
            )
        elif self.demosaic_pattern is not None or not self.paper_colours:
            rows = row_weights_of(x, params)[:, None, :, None]
        else:
            return self._apply_paper(x, params)
        gain, offset = self.bayer["gain"], self.bayer["offset"]
        if self.demosaic_pattern is None:
            return torch.lerp(x, physics.em_color_map(x, gain, offset), rows.to(x.dtype)).clamp_(0.0, 1.0)
        terms, weights = physics.bayer_line_terms(x, self.demosaic_pattern)
        return physics.em_demosaic_rows(terms, weights, x, rows[:, 0, :, 0], gain, offset)

    @property
    def paper_colours(self) -> bool:
        """Whether mis-decoded rows take the paper's colour map (its fast in-place kernels, ``_corrupt_``)."""
        return (self.bayer["gain"], self.bayer["offset"]) == (GREEN_GAIN, GREEN_OFFSET)

    def _apply_uint8(self, x: torch.Tensor, params: dict[str, torch.Tensor]) -> torch.Tensor:
        if self.model == "bayer_phase_flip" or self.demosaic_pattern is not None or not self.paper_colours:
            return NotImplemented
        return self._apply_paper(x, params)

    def _apply_paper(self, x: torch.Tensor, params: dict[str, torch.Tensor]) -> torch.Tensor:
        return em_color_strip_rgb(
            x, params["num_stripes"], params["band_fraction"], params["next_num_stripes"], params["mix"]
        )

    def extra_repr(self) -> str:
        return (
            super().extra_repr()
            + ("" if self.num_stripes is None else f", num_stripes={self.num_stripes}")
            + (
                ""
                if self.paper_colours
                else f", gain={self.bayer['gain']!r}, offset={self.bayer['offset']!r}"
            )
            + ("" if self.demosaic_pattern is None else f", demosaic_pattern={self.demosaic_pattern!r}")
        )
