"""EM truncation: electromagnetic interference corrupts the camera's frame-buffer addresses (paper, Method and
Appendix A, Algorithm "EM Truncation Attack"; after GlitchHiker, Jiang et al. 2023).

The paper's algorithm, for a truncation ratio ``r`` and an image of height ``h``::

    start = int(h * r); num = int(h * r)
    delete rows [start, start + num) and append the last ``num`` rows of the frame

so a band of ``num`` rows vanishes, everything below it moves up and the bottom ``num`` rows appear twice.

Deviations from the paper's code (and why):

* **Band start clamped.** The paper's ``start = int(h*r)`` makes the deleted band coincide with the appended tail
  at ``r = 0.5`` (the output equals the input), and for ``r > 0.5`` the output is *taller* than the input. Here
  ``start = max(0, min(int(h*r), h - 2*num))``: identical to the paper for ``r <= 1/3`` (the paper's range, levels
  0.1/0.2/0.3), and for ``1/3 < r <= 0.5`` the band slides up so that it never overlaps the appended tail. The
  output always has height ``h``. Ratios above 0.5 are rejected: with at most ``h`` rows there is no way to lose
  more than half of them and still append as many.
* **Vectorised per sample, exact in any dtype** (no float round trip): one gather of whole rows over the flattened
  batch (``index_select``); for one ratio shared by the batch the row index is cached, so one image costs about what
  the paper's ``np.delete`` / ``np.append`` does.
* **"random"** draws the authors' adversarial-training ratio ``r ~ U(0.1, 0.3)``.

Calibrated options (``lerobot-phantom-calibrate --attack em_truncation`` writes them; issue 12):
``ratio_per_intensity`` replaces the level table by the measured line ``r = a s``, and ``free_band_position``
draws each sample's band start uniformly over every row from the top to ``h - num`` (the interference corrupts
the buffer address at a moment set by its timing, not by how many rows are lost; at ``h - num`` the band is the
tail itself and the frame passes unchanged). ``ratio_per_intensity_spread`` and ``ratio_jitter`` draw each
sample's ratio from the law the calibration predicts held-out frames with, ``r = (a + w u) s + d z``, ``u``
uniform on ``[-1, 1]``, ``z`` standard normal, clipped to ``[0, 0.5]``: ``w`` is half the range of slopes the
measured frames leave possible (their counts are floors; 0 where they contradict one line), ``d`` the
frame-to-frame jitter of the interference's timing: a number, or equally likely values of which each sample draws
one (the calibration writes its posterior's quantiles, so a frame a few rows off the line stays possible). At zero
intensity there is no attack, jitter or not.

Note on "distortion": the number of lost rows, ``int(h*r)``, grows with ``r``. The mean absolute difference to
the clean frame does *not* always grow: only rows ``[start, h - num)`` change (shifted by ``num`` rows), and that
band shrinks as ``r`` grows, so on texture-free noise images the paper's strong level differs from the clean image
in fewer pixels than its weak level does.
"""

from __future__ import annotations

import functools
import numbers
from collections.abc import Sequence
from typing import ClassVar

import torch

from lerobot_phantom.transforms.base import CameraAttack, check_image
from lerobot_phantom.transforms.intensity import IntensitySpec, RandomParameter, interpolate_levels

MAX_RATIO = 0.5


def truncation_row_index(height: int, ratio: torch.Tensor) -> torch.Tensor:
    """Source row of every output row, ``(B, height)`` long, for per-sample ratios ``(B,)`` in [0, 0.5]."""
    return rows_after_losing(height, torch.floor(height * ratio).long())


def paper_band_start(height: int, num: torch.Tensor) -> torch.Tensor:
    """The paper's band start ``int(h r)``, which is the count ``num`` itself, clamped so that the band never
    overlaps the appended tail (the module docstring's first deviation)."""
    return torch.clamp(torch.minimum(num, height - 2 * num), min=0)


def rows_after_losing(height: int, num: torch.Tensor, start: torch.Tensor | None = None) -> torch.Tensor:
    """Source row of every output row, ``(B, height)`` long, when each sample loses ``num`` rows (long ``(B,)``)
    from ``start`` (long ``(B,)``, at most ``height - num``; by default :func:`paper_band_start`) and repeats its
    last ``num`` rows. The calibration's frame model predicts frames with it too."""
    if start is None:
        start = paper_band_start(height, num)
    rows = torch.arange(height, device=num.device).unsqueeze(0)  # (1, H)
    num, start = num.unsqueeze(1), start.unsqueeze(1)
    shifted = (rows >= start) & (rows < height - num)
    return torch.where(shifted, rows + num, rows)


def _ratios(ratio: float | torch.Tensor, batch: int) -> list[float]:
    """Validated per-sample ratios as Python floats (one host sync for a tensor, none for a float)."""
    values = ratio.detach().reshape(-1).tolist() if isinstance(ratio, torch.Tensor) else [float(ratio)]
    if len(values) == 1:
        values = values * batch
    elif len(values) != batch:
        raise ValueError(
            f"ratio must be a scalar or have one value per sample ({batch}), got {len(values)} values"
        )
    if not all(0.0 <= r <= MAX_RATIO for r in values):  # also rejects NaN
        raise ValueError(f"EM truncation ratio must lie in [0, {MAX_RATIO}], got {values}")
    return values


def em_truncation(
    image: torch.Tensor, ratio: float | torch.Tensor, start_fraction: torch.Tensor | None = None
) -> torch.Tensor:
    """EM truncation of ``image`` (``(..., C, H, W)``, any dtype) with truncation ratio ``ratio`` in [0, 0.5].

    ``ratio`` is a float or a tensor with one value per image of the batch (leading dims flattened). Without
    ``start_fraction`` the band starts where the paper puts it; with it (one value in [0, 1) per image), at
    ``floor(start_fraction * (h - num + 1))``, anywhere from the top to ``h - num``. Returns a new tensor of the
    input's shape, dtype and device. See the module docstring for the algorithm and the fix.
    """
    check_image(image)
    channels, height, width = image.shape[-3:]
    batch = image.numel() // (channels * height * width)
    ratios = _ratios(ratio, batch)
    lost = {int(height * r) for r in ratios}  # int(h * r) as the paper (and truncation_row_index)
    if start_fraction is None and len(lost) == 1:  # one ratio for the batch: a cached row index
        index = _shared_row_index(batch * channels, height, lost.pop(), image.device)
    else:  # per-sample ratios or starts: still one gather of whole rows over the flattened batch
        num = torch.floor(height * torch.tensor(ratios, dtype=torch.float64, device=image.device)).long()
        start = None
        if start_fraction is not None:
            fraction = start_fraction.detach().reshape(-1).to(device=image.device, dtype=torch.float64)
            if fraction.numel() != batch or not bool(((fraction >= 0) & (fraction < 1)).all()):
                raise ValueError(
                    f"start_fraction needs one value in [0, 1) per image ({batch}), got {fraction.tolist()}"
                )
            start = torch.floor(fraction * (height - num + 1)).long()
        per_image = rows_after_losing(height, num, start)
        index = per_image.repeat_interleave(channels, dim=0) + height * torch.arange(
            batch * channels, device=image.device
        ).unsqueeze(1)
        index = index.reshape(-1)
    return image.reshape(-1, width).index_select(0, index).view(image.shape)


@functools.lru_cache(maxsize=32)
def _shared_row_index(planes: int, height: int, num: int, device: torch.device) -> torch.Tensor:
    """Source row of every row of ``planes`` stacked ``height``-row planes that all lose ``num`` rows."""
    rows = rows_after_losing(height, torch.tensor([num]))[0]
    offsets = height * torch.arange(planes).unsqueeze(1)
    return (rows.unsqueeze(0) + offsets).reshape(-1).to(device)


class EMTruncation(CameraAttack):
    """EM truncation attack as a torchvision v2 transform.

    Intensity -> ratio: 0 (identity) / 0.1 (weak) / 0.2 (medium) / 0.3 (strong), piecewise linear in between
    (paper, Table 2). ``ratio=`` fixes the physical ratio (in [0, 0.5]) whatever the intensity, calibrated or
    not. The calibrated options (``ratio_per_intensity``, its ``_spread``, ``ratio_jitter``,
    ``free_band_position``): module docstring.
    """

    name: ClassVar[str] = "em_truncation"
    LEVEL_RATIOS: ClassVar[tuple[float, float, float, float]] = (0.0, 0.1, 0.2, 0.3)
    # the authors' adversarial training: ratio uniform in [0.1, 0.3]
    random_parameter: ClassVar[RandomParameter] = RandomParameter(0.1, 0.3, levels=LEVEL_RATIOS)

    def __init__(
        self,
        intensity: IntensitySpec = "medium",
        *,
        ratio: float | None = None,
        ratio_per_intensity: float | None = None,
        ratio_per_intensity_spread: float = 0.0,
        ratio_jitter: float | Sequence[float] = 0.0,
        free_band_position: bool = False,
        seed: int | None = None,
        generator: torch.Generator | None = None,
    ) -> None:
        super().__init__(intensity, seed=seed, generator=generator)
        one_jitter = isinstance(ratio_jitter, numbers.Real)  # numpy's scalars too
        jitters = (ratio_jitter,) if one_jitter else tuple(ratio_jitter)
        if not jitters:
            raise ValueError(
                "ratio_jitter must be a number or a non-empty sequence of equally likely numbers"
            )
        for option, value in (
            ("ratio", ratio),
            ("ratio_per_intensity", ratio_per_intensity),
            ("ratio_per_intensity_spread", ratio_per_intensity_spread),
            *(("ratio_jitter", jitter) for jitter in jitters),
        ):
            if value is not None and not (0.0 <= float(value) <= MAX_RATIO):
                raise ValueError(f"{option} must lie in [0, {MAX_RATIO}], got {value!r}")
        if (ratio_per_intensity_spread or any(jitters)) and ratio_per_intensity is None and ratio is None:
            raise ValueError(
                "ratio_per_intensity_spread and ratio_jitter spread the measured line: they need ratio_per_intensity"
            )
        if ratio_per_intensity is not None and ratio_per_intensity_spread > ratio_per_intensity:
            raise ValueError(
                f"ratio_per_intensity_spread ({ratio_per_intensity_spread!r}) must not exceed ratio_per_intensity "
                f"({ratio_per_intensity!r}): the slopes would go below 0"
            )
        self.ratio = None if ratio is None else float(ratio)
        self.ratio_per_intensity = None if ratio_per_intensity is None else float(ratio_per_intensity)
        self.ratio_per_intensity_spread = float(ratio_per_intensity_spread)
        self.ratio_jitter = float(jitters[0]) if one_jitter else tuple(map(float, jitters))
        self._jitters = tuple(map(float, jitters))
        self.free_band_position = bool(free_band_position)

    def ratio_for(self, s: torch.Tensor) -> torch.Tensor:
        """The truncation ratio used at intensity ``s`` (per sample); with a spread or jitter, the centre of the
        ratios drawn."""
        if self.ratio is not None:
            return torch.full_like(s, self.ratio, dtype=torch.float32)
        if self.ratio_per_intensity is not None:
            return (self.ratio_per_intensity * s).to(torch.float32)
        return interpolate_levels(s, self.LEVEL_RATIOS)

    def _sample(self, s, height, width, generator, device):
        values = s.tolist()
        if self.ratio is None and (self.ratio_per_intensity_spread or any(self._jitters)):
            params = {"ratio": self._spread_ratio(s, generator).to(device)}
        elif (
            len(set(values)) == 1
        ):  # a fixed intensity: the level map once per value, not a dozen tiny ops per call
            ratio = self._cached(("ratio", values[0]), lambda: float(self.ratio_for(s[:1])[0]))
            params = {"ratio": torch.full((len(values),), ratio, dtype=torch.float32, device=device)}
        else:
            params = {"ratio": self.ratio_for(s).to(device)}
        if self.free_band_position:
            if generator is None:
                raise ValueError("free_band_position=True needs a torch.Generator (pass generator= or seed=)")
            start = torch.rand(len(values), generator=generator, dtype=torch.float64, device=generator.device)
            params["start_fraction"] = start.to(device)
        return params

    def _spread_ratio(self, s: torch.Tensor, generator: torch.Generator | None) -> torch.Tensor:
        """Each sample's ratio ``(a + w u) s + d z`` (module docstring), clipped to ``[0, 0.5]``, ``d`` drawn from
        the equally likely jitters where there are several; none at zero intensity."""
        if generator is None:
            raise ValueError(
                "ratio_per_intensity_spread and ratio_jitter need a torch.Generator (pass generator= or seed=)"
            )
        u = torch.rand(len(s), generator=generator, dtype=torch.float64, device=generator.device).cpu()
        z = torch.randn(len(s), generator=generator, dtype=torch.float64, device=generator.device).cpu()
        s = s.detach().cpu().to(torch.float64)
        jitter = torch.tensor(self._jitters, dtype=torch.float64)
        if len(jitter) > 1:  # one draw more only where there is a choice: a single jitter keeps its streams
            jitter = jitter[
                torch.randint(len(jitter), (len(s),), generator=generator, device=generator.device).cpu()
            ]
        slope = self.ratio_per_intensity + self.ratio_per_intensity_spread * (2 * u - 1)
        ratio = torch.clamp(slope * s + jitter * z, 0.0, MAX_RATIO)
        return torch.where(s > 0, ratio, torch.zeros_like(ratio)).to(torch.float32)

    def _apply(self, x: torch.Tensor, params: dict[str, torch.Tensor]) -> torch.Tensor:
        return em_truncation(x, params["ratio"], params.get("start_fraction"))

    def apply_params(self, img: torch.Tensor, params: dict[str, torch.Tensor]) -> torch.Tensor:
        # A row gather is exact in any dtype and channel count, so skip the float RGB round trip of the base.
        return em_truncation(img, params["ratio"], params.get("start_fraction"))

    def extra_repr(self) -> str:
        extra = "" if self.ratio is None else f", ratio={self.ratio}"
        if self.ratio_per_intensity is not None:
            extra += f", ratio_per_intensity={self.ratio_per_intensity}"
        if self.ratio_per_intensity_spread or any(self._jitters):
            extra += f", ratio_per_intensity_spread={self.ratio_per_intensity_spread}"
            extra += f", ratio_jitter={self.ratio_jitter}"
        return super().extra_repr() + extra + (", free_band_position=True" if self.free_band_position else "")
