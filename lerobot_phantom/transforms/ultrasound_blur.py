"""Ultrasound blur: ultrasound resonates the camera's IMU, the stabiliser "corrects" motion that never happened and
the frame is smeared (paper, Method and Appendix A, Algorithm "Ultrasound Blur Attack"; after Poltergeist,
Ji et al. 2021).

Every output pixel is the mean of the input pixels along its motion path, which combines a linear displacement,
a rotation ``theta`` about the image centre and a radial (zoom) component ``scale``. As in the paper's released
code, the path is written in (row, column) coordinates with centre ``(c0, c1) = (int(h/2), int(w/2))``: for the
pixel at row ``x``, column ``y``, with ``R, alpha`` its polar coordinates about the centre (``alpha`` measured from
the row axis towards the column axis),

    X = d_row - scale * R * cos(alpha),   Y = d_col - scale * R * sin(alpha)
    N = min(int(max(|R cos(alpha + theta) + X + c0 - x|, |R sin(alpha + theta) + Y + c1 - y|)), 100)
    samples i = 0..N, n = i / N:  (int(R cos(alpha + n theta) + n X + c0), int(R sin(alpha + n theta) + n Y + c1))

and the pixel is the mean of the in-bounds samples (unchanged when ``N = 0``). ``int`` truncates toward zero.

Parameters here: ``dx`` is the horizontal (column) and ``dy`` the vertical (row) displacement in pixels, i.e. the
paper code's ``dy`` and ``dx`` respectively (its ``x`` is the row); ``theta_deg`` turns the row axis towards the
column axis (counter-clockwise on screen); ``scale`` in [0, 1] pulls the path end towards the centre. Paper
levels: ``dx = dy = 5 / 10 / 20`` pixels (no rotation, no radial part) at weak / medium / strong on the 256x256
reference image (``base.REFERENCE_SIZE``); the transform scales ``dx`` with ``W / 256`` and ``dy`` with
``H / 256`` so every camera resolution sees the same blur. A measured blur (``displacement_per_intensity_px``, the
vector ``lerobot-phantom-calibrate`` fits: pixels at the reference scale of the image's longer side, growing
linearly with the intensity) is scaled by ``max(H, W) / 256`` on both axes instead: a camera's pixels are square,
so the stabiliser's motion keeps its direction at every resolution.

Deviations from the paper's code (and why):

* **Every pixel.** The released code visits every second pixel in each direction and copies its average into a
  2x2 block, halving the resolution of the blurred image. Every pixel gets its own path here.
* **atan2.** ``delta = atan(dy/dx)`` divides by zero for a purely vertical blur; ``atan2`` is identical for
  ``dx > 0`` and defined everywhere (the linear term is simply ``(d_row, d_col)``).
* **Exact integer arithmetic.** In float64, ``R*cos(alpha) + c0`` lands a few ulp below the integer row for ~8 %
  of pixels and the paper's ``int()`` then truncates one pixel short; likewise ``N`` comes out one short for
  ~0.8 % of pixels. A 1e-6 pixel snap before truncation removes this round-off noise.

Distortion grows with the intensity on camera-like (smooth) frames. On tiny noise images it can dip: when the
path is only a pixel or two long, ``int()`` quantises its direction, so a slightly longer path may average a
different (not a larger) set of neighbours.

Fast path: with no rotation and no radial part (the paper's levels) the path offsets are the same for every pixel,
so the blur is a sum of ``N + 1`` shifted views of the image with an in-bounds count map. On the paper's diagonal
(and any axis-aligned path) sample ``i`` sits exactly ``i`` pixels along the direction, so the sum is a box: summed
by doubling in uint8's int16 (``~2 log2(N)`` shifted adds, 5 instead of 17 at the strong level on 224x224), by one
strided reduction in float; other directions take ``~N`` strided adds. The general path gathers the ``N + 1``
samples of every pixel. A batch is grouped by identical parameters (one pass per distinct displacement: at most 16
under ``"random"``, which draws the authors' whole-pixel ``randint(5, 20)``; the geometry of each displacement is
cached). uint8 images are blurred on their 0-255
values: the sums in int16 (exact), the division in float32, rounded once (half to even, as the float path:
``1.5 * 2**23`` is added in the division's pass, which leaves the rounded mean in the low byte of the float's bit
pattern), with no scaling to [0, 1] and back. Cost, measured (``scripts/bench_transforms.py``): a few images at a
time in cache, the strong level takes about 9 passes over the frame (widen into a buffer zero-padded by the path's
length, 5 shifted adds of one op each, convert, divide, narrow); every one of them costs 2-10 times a uint8
``torch.clone``, so the uint8 blur stays near 0.02x clone (the bench prints this floor). Float images on a box
path are instead copied into a zero-padded buffer in which the path of every pixel is one strided view, summed by
one reduction (from the cache) and divided straight into the output.
"""

from __future__ import annotations

import functools
import math
import numbers
from collections.abc import Callable, Sequence
from typing import ClassVar

import torch

from lerobot_phantom.transforms import physics
from lerobot_phantom.transforms.base import (
    REFERENCE_SIZE,
    CameraAttack,
    check_image,
    from_float_rgb,
    from_uint8_rgb,
    to_float_rgb,
    to_rgb,
)
from lerobot_phantom.transforms.intensity import IntensitySpec, RandomParameter, interpolate_levels

MAX_SAMPLES = 100
SNAP = 1e-6
_CHUNK_ELEMENTS = 1 << 20
_FLOAT_BOX_CHUNK_ELEMENTS = 3 << 17  # two 224x224 RGB images (measured: 1 to 6 within 10%)
ROUNDER = 1.5 * 2**23
"""Added to a float32 value v in [0, 2**22), it leaves round(v) (half to even) in the low bits of the bit pattern."""
LEVEL_DISPLACEMENT_PX: tuple[float, float, float, float] = (0.0, 5.0, 10.0, 20.0)


def _per_sample(value: float | torch.Tensor, batch: int, what: str) -> list[float]:
    t = torch.as_tensor(value, dtype=torch.float64).reshape(-1)
    if t.numel() == 1:
        t = t.expand(batch)
    elif t.numel() != batch:
        raise ValueError(
            f"{what} must be a scalar or have one value per sample ({batch}), got {t.numel()} values"
        )
    if not torch.isfinite(t).all():
        raise ValueError(f"{what} must be finite, got {t.tolist()}")
    return t.tolist()


def _measured_displacement(value: Sequence[float] | None) -> tuple[float, float] | None:
    """``displacement_per_intensity_px`` checked: None, or two finite numbers (a JSON list from calibrated.json)."""
    if value is None:
        return None
    pair = isinstance(value, Sequence) and not isinstance(value, str) and len(value) == 2
    if not (pair and all(isinstance(v, numbers.Real) and math.isfinite(v) for v in value)):
        raise ValueError(
            f"displacement_per_intensity_px must be two finite numbers (dx, dy) in reference pixels, got {value!r}"
        )
    return float(value[0]), float(value[1])


def _axis_spans(size: int, offset: float) -> list[tuple[int, int, int]]:
    """``(dst_start, dst_stop, src_start)`` runs of ``dst -> int(dst + offset)`` that stay inside ``[0, size)``."""
    shifted = offset + SNAP
    k = math.floor(shifted)
    spans = []
    start, stop = max(0, -k), min(size, size - k)
    if start < stop:
        spans.append((start, stop, start + k))
    # int() truncates toward zero: the one position landing in (-1, 0) still reads index 0
    special = -k - 1
    if k < 0 and shifted > k and special < size:
        spans.append((special, special + 1, 0))
    return spans


def _axis_valid(
    size: int, spans_per_sample: list[list[tuple[int, int, int]]], device: torch.device
) -> torch.Tensor:
    """``(samples, size)`` 0/1: which destinations each sample's spans cover (built in one go, not per span)."""
    starts, stops = [], []
    for spans in spans_per_sample:
        # at most a main run and the single truncated-to-zero position: pad to two runs per sample
        runs = [*spans, (0, 0, 0), (0, 0, 0)][:2]
        starts.append([r[0] for r in runs])
        stops.append([r[1] for r in runs])
    positions = torch.arange(size, device=device)
    lo = torch.tensor(starts, device=device)[:, :, None]
    hi = torch.tensor(stops, device=device)[:, :, None]
    return ((positions >= lo) & (positions < hi)).any(dim=1).to(torch.float32)


def _shift_add(
    a: torch.Tensor, b: torch.Tensor, k: int, step: tuple[int, int], out: torch.Tensor
) -> torch.Tensor:
    """``out = a + b`` shifted by ``k`` steps along ``step`` (``out[r, c] = a[r, c] + b[r + k sr, c + k sc]``, zero
    where that leaves the image). ``out`` must not overlap ``a`` or ``b``."""
    height, width = a.shape[-2:]
    dr, dc = k * step[0], k * step[1]
    r0, r1, c0, c1 = max(0, -dr), min(height, height - dr), max(0, -dc), min(width, width - dc)
    if r0 >= r1 or c0 >= c1:
        return out.copy_(a)
    torch.add(a[..., r0:r1, c0:c1], b[..., r0 + dr : r1 + dr, c0 + dc : c1 + dc], out=out[..., r0:r1, c0:c1])
    # the border strips b does not reach keep a (empty strips are skipped: each op costs a dispatch)
    for rows, cols in ((slice(0, r0), slice(None)), (slice(r1, height), slice(None))):
        if rows.start < rows.stop:
            out[..., rows, cols].copy_(a[..., rows, cols])
    for cols in (slice(0, c0), slice(c1, width)):
        if cols.start < cols.stop:
            out[..., r0:r1, cols].copy_(a[..., r0:r1, cols])
    return out


def _padded_shift_add(
    a: torch.Tensor, b: torch.Tensor, k: int, step: tuple[int, int], out: torch.Tensor
) -> torch.Tensor:
    """``_shift_add`` on buffers zero-padded by at least the path's length below and right of the image: one op
    over the rows and columns where ``b``'s shifted view exists (the rest of ``out`` keeps stale values, which no
    valid sum reads: a sum of ``n`` samples is exact on the rows and columns whose ``n`` samples lie in the buffer,
    and every later add reads it only there). No border copies: one op per add instead of up to five."""
    dr, dc = k * step[0], k * step[1]
    rows, cols = a.shape[-2] - dr, a.shape[-1] - dc
    torch.add(a[..., :rows, :cols], b[..., dr:, dc:], out=out[..., :rows, :cols])
    return out


def _box_sum(
    x: torch.Tensor,
    step: tuple[int, int],
    length: int,
    scratch: list[torch.Tensor],
    shift_add: Callable[..., torch.Tensor] = _shift_add,
) -> torch.Tensor:
    """``sum_{i < length} x[r + i sr, c + i sc]`` (zero outside) by doubling: ~2 log2(length) shifted adds instead of
    ``length`` (5 instead of 17 at the paper's strong level on 224x224), summed as a tree (float error ~log2).

    ``scratch``: four buffers shaped like ``x`` (reused by every chunk of a batch: no allocation per add). The
    result is one of them, or ``x`` itself when ``length == 1``. ``shift_add``: ``_shift_add``, or
    ``_padded_shift_add`` when ``x`` is zero-padded by ``length - 1`` along ``step``."""
    free = list(scratch)
    result, covered, power, size = None, 0, x, 1
    while True:
        if length & 1:
            if result is None:
                result, covered = power, size
            else:
                target = free.pop()
                shift_add(result, power, covered, step, target)
                if result is not x and result is not power:
                    free.append(result)
                result, covered = target, covered + size
        length >>= 1
        if not length:
            return result
        target = free.pop()
        shift_add(power, power, size, step, target)
        if power is not x and power is not result:
            free.append(power)
        power, size = target, size * 2


@functools.lru_cache(maxsize=64)
def _linear_geometry(
    height: int, width: int, d_row: float, d_col: float
) -> tuple[int, tuple[int, int] | None, list, torch.Tensor]:
    """Per image size and displacement: (samples - 1, the box step or None, the samples' spans, the in-bounds
    count map ``(H, W)`` float32 on the CPU). Pure, so cached: a batch of one displacement costs no Python per
    image, and "random"'s at most 16 displacements are computed once."""
    num = min(int(max(abs(d_row), abs(d_col)) + SNAP), MAX_SAMPLES)
    spans = [
        (_axis_spans(height, i / num * d_row), _axis_spans(width, i / num * d_col)) for i in range(num + 1)
    ]
    row_valid = _axis_valid(height, [rows for rows, _ in spans], torch.device("cpu"))
    col_valid = _axis_valid(width, [cols for _, cols in spans], torch.device("cpu"))
    count = row_valid.T @ col_valid  # (H, W) in-bounds samples; sample 0 is the pixel itself
    # The paper's diagonal (and any axis-aligned path): sample i sits exactly i steps of (0 or 1, 0 or 1) away,
    # so the path is a box along one direction, summed by doubling.
    shifts = [
        (math.floor(i / num * d_row + SNAP), math.floor(i / num * d_col + SNAP)) for i in range(num + 1)
    ]
    step = shifts[1]
    is_box = step in ((1, 1), (1, 0), (0, 1)) and all(
        s == (i * step[0], i * step[1]) for i, s in enumerate(shifts)
    )
    return num, step if is_box else None, spans, count


def _linear_blur(x: torch.Tensor, d_row: float, d_col: float, upper: float | None = None) -> torch.Tensor:
    """Fast path: the paper's path with no rotation and no radial part, as a sum of shifted views.

    Float ``x``: the mean, clamped to [0, upper] when ``upper`` is given (chunk by chunk while it is in cache; a
    fresh tensor then). uint8 ``x``: the mean of the 0-255 values rounded to uint8; the sums run in int16 (exact:
    at most 101 x 255), only the division in float32, so the result equals the float path's rounded mean."""
    if min(int(max(abs(d_row), abs(d_col)) + SNAP), MAX_SAMPLES) <= 0:
        return x if x.dtype == torch.uint8 or upper is None else x.clamp(0.0, upper)
    out = torch.empty_like(x)
    _linear_blur_into(out, x, list(range(x.shape[0])), d_row, d_col, upper)
    return out


def _linear_blur_into(
    out: torch.Tensor, x: torch.Tensor, members: list[int], d_row: float, d_col: float, upper: float | None
) -> None:
    """``out[members] = _linear_blur(x[members], ...)`` without gathering or scattering the batch: a few images
    at a time are read into a scratch that stays in cache (views when they are consecutive) and written back."""
    _, channels, height, width = x.shape
    if min(int(max(abs(d_row), abs(d_col)) + SNAP), MAX_SAMPLES) <= 0:
        for i in members:
            out[i].copy_(x[i] if x.dtype == torch.uint8 or upper is None else x[i].clamp(0.0, upper))
        return
    num, step, spans, count = _linear_geometry(height, width, float(d_row), float(d_col))
    if step is not None and x.dtype != torch.uint8:
        _box_blur_float_into(out, x, members, step, num + 1, count.to(x.device, x.dtype), upper)
        return
    integer = x.dtype == torch.uint8
    work_dtype = torch.int16 if integer else x.dtype
    count = count.to(x.device, torch.float32 if integer else x.dtype)
    per_chunk = min(len(members), max(1, _CHUNK_ELEMENTS // x[0].numel()))  # a few images stay in cache
    shape = (per_chunk, channels, height, width)
    # uint8 box paths sum in buffers zero-padded by the path's length (one op per doubling add, no border copies)
    pad_rows, pad_cols = (num * step[0], num * step[1]) if integer and step else (0, 0)
    padded = (per_chunk, channels, height + pad_rows, width + pad_cols)
    scratch = [torch.empty(padded, dtype=work_dtype, device=x.device) for _ in range(4 if step else 1)]
    gathered = torch.zeros(padded, dtype=work_dtype, device=x.device)
    interior = gathered[:, :, :height, :width]
    quotient = torch.empty(shape, dtype=torch.float32, device=x.device) if integer else None
    rounder = torch.tensor(ROUNDER, dtype=torch.float32, device=x.device)
    for start in range(0, len(members), per_chunk):
        chunk = members[start : start + per_chunk]
        size, first = len(chunk), chunk[0]
        consecutive = chunk[-1] - first == size - 1  # members are increasing
        if consecutive and not integer:
            part = x[first : first + size]
        else:
            part = interior[:size]
            if consecutive:
                part.copy_(x[first : first + size])
            else:
                for j, i in enumerate(chunk):
                    part[j].copy_(x[i])
        if step is not None and integer:
            buffers = [buffer[:size] for buffer in scratch]
            total = _box_sum(gathered[:size], step, num + 1, buffers, _padded_shift_add)
            total = total[:, :, :height, :width]
        elif step is not None:
            total = _box_sum(part, step, num + 1, [buffer[:size] for buffer in scratch])
        else:
            total = scratch[0][:size].copy_(part)  # sample i = 0: offset (0, 0)
            for row_spans, col_spans in spans[1:]:
                for r0, r1, rs in row_spans:
                    for c0, c1, cs in col_spans:
                        total[..., r0:r1, c0:c1] += part[..., rs : rs + r1 - r0, cs : cs + c1 - c0]
        if integer:
            # ROUNDER + total / count, in float32 (whose unit in the last place is 1 there), is the mean rounded half
            # to even in the low bits of its bit pattern: read as int32 and narrowed to uint8 (which keeps the low
            # byte), one division pass and one narrowing replace divide, round, float -> int16 -> uint8
            widened = quotient[:size].copy_(total)  # addcdiv would convert int16 into a fresh float32 tensor
            result = torch.addcdiv(rounder, widened, count, out=widened).view(torch.int32)
        elif consecutive:  # the mean straight into the output, clamped while it is in cache
            result = torch.div(total, count, out=out[first : first + size])
            if upper is not None:
                result.clamp_(0.0, upper)
            continue
        else:
            result = torch.div(total, count, out=part)  # the gathered copy, no longer needed
            if upper is not None:
                result.clamp_(0.0, upper)
        if consecutive:
            out[first : first + size].copy_(result)
        else:
            for j, i in enumerate(chunk):
                out[i].copy_(result[j])


def _box_blur_float_into(
    out: torch.Tensor,
    x: torch.Tensor,
    members: list[int],
    step: tuple[int, int],
    length: int,
    count: torch.Tensor,
    upper: float | None,
) -> None:
    """The box path on float images: each image is copied into a buffer padded with ``length - 1`` zero rows
    and/or columns along ``step``, where the path of every pixel is one strided view, and summed by one reduction
    over it (``length`` reads per pixel from the cache, one pass; measured 0.18 vs 0.23 ms per 224x224 image for the
    doubling's 5 shifted adds at the strong level). The mean goes straight into the output."""
    _, channels, height, width = x.shape
    pad_rows, pad_cols = (length - 1) * step[0], (length - 1) * step[1]
    per_chunk = min(len(members), max(1, _FLOAT_BOX_CHUNK_ELEMENTS // x[0].numel()))
    padded = torch.zeros(
        (per_chunk, channels, height + pad_rows, width + pad_cols), dtype=x.dtype, device=x.device
    )
    s_image, s_channel, s_row, _ = padded.stride()
    path = padded.as_strided(
        (per_chunk, channels, length, height, width),
        (s_image, s_channel, step[0] * s_row + step[1], s_row, 1),
    )
    interior = padded[:, :, :height, :width]
    total = torch.empty((per_chunk, channels, height, width), dtype=x.dtype, device=x.device)
    for start in range(0, len(members), per_chunk):
        chunk = members[start : start + per_chunk]
        size, first = len(chunk), chunk[0]
        consecutive = chunk[-1] - first == size - 1  # members are increasing
        if consecutive:
            interior[:size].copy_(x[first : first + size])
        else:
            for j, i in enumerate(chunk):
                interior[j].copy_(x[i])
        torch.sum(path[:size], dim=2, out=total[:size])
        targets = [out[first : first + size]] if consecutive else [out[i] for i in chunk]
        sums = [total[:size]] if consecutive else list(total[:size])
        for target, summed in zip(targets, sums, strict=True):
            torch.div(summed, count, out=target)
            if upper is not None:
                target.clamp_(0.0, upper)


def _general_blur(
    x: torch.Tensor, d_row: float, d_col: float, theta_deg: float, scale: float, upper: float | None = None
) -> torch.Tensor:
    """General path (rotation and/or radial part): gather the samples of every pixel, float64 coordinates."""
    batch, channels, height, width = x.shape
    device = x.device
    c0, c1 = height // 2, width // 2
    theta = theta_deg * math.pi / 180.0
    rows = torch.arange(height, device=device, dtype=torch.float64).unsqueeze(1)
    cols = torch.arange(width, device=device, dtype=torch.float64).unsqueeze(0)
    radius = torch.hypot(rows - c0, cols - c1)
    alpha = torch.atan2(cols - c1, rows - c0)
    x_cos = d_row - scale * radius * torch.cos(alpha)
    y_sin = d_col - scale * radius * torch.sin(alpha)
    end = torch.maximum(
        (radius * torch.cos(alpha + theta) + x_cos + c0 - rows).abs(),
        (radius * torch.sin(alpha + theta) + y_sin + c1 - cols).abs(),
    )
    num = torch.clamp(torch.trunc(end + SNAP), max=MAX_SAMPLES)  # (H, W)
    blurred = num > 0
    safe_num = torch.where(blurred, num, torch.ones_like(num))
    flat = x.reshape(batch, channels, height * width)
    total = torch.zeros_like(flat)
    count = torch.zeros(height * width, device=device, dtype=x.dtype)
    # without rotation the circular term is the same for every sample: compute it once
    still_row, still_col = radius * torch.cos(alpha) + c0 + SNAP, radius * torch.sin(alpha) + c1 + SNAP
    for i in range(int(num.max().item()) + 1):
        n = i / safe_num
        if theta == 0.0:
            row_t = torch.trunc(still_row + n * x_cos)
            col_t = torch.trunc(still_col + n * y_sin)
        else:
            row_t = torch.trunc(radius * torch.cos(alpha + n * theta) + n * x_cos + c0 + SNAP)
            col_t = torch.trunc(radius * torch.sin(alpha + n * theta) + n * y_sin + c1 + SNAP)
        valid = blurred & (i <= num) & (row_t >= 0) & (row_t < height) & (col_t >= 0) & (col_t < width)
        index = torch.where(valid, row_t * width + col_t, torch.zeros_like(row_t)).long().reshape(1, 1, -1)
        weight = valid.reshape(-1).to(x.dtype)
        # gather, not index_select: index_select along the last dim is ~50x slower on CPU
        total += flat.gather(2, index.expand(batch, channels, -1)) * weight
        count += weight
    keep = count == 0
    out = torch.where(keep, flat, total / torch.where(keep, torch.ones_like(count), count))
    out = out.reshape(batch, channels, height, width)
    return out if upper is None else out.clamp_(0.0, upper)


def ultrasound_blur_float(
    x: torch.Tensor,
    dx: float | torch.Tensor,
    dy: float | torch.Tensor,
    theta_deg: float | torch.Tensor = 0.0,
    scale: float | torch.Tensor = 0.0,
    upper: float | None = None,
) -> torch.Tensor:
    """``ultrasound_blur`` on RGB ``(B, 3, H, W)`` (the transform's inner op): float in [0, 1], or uint8, blurred on
    its 0-255 values and rounded once. ``upper`` (float only): also clamp the result to [0, upper] while it is in
    cache (a fresh tensor then; the mean of in-range values is in range)."""
    batch = x.shape[0]
    columns = _per_sample(dx, batch, "dx")
    rows = _per_sample(dy, batch, "dy")
    angles = _per_sample(theta_deg, batch, "theta_deg")
    scales = _per_sample(scale, batch, "scale")
    groups: dict[tuple[float, float, float, float], list[int]] = {}
    for i, key in enumerate(zip(rows, columns, angles, scales, strict=True)):
        groups.setdefault(key, []).append(i)
    out = torch.empty_like(x)
    for (d_row, d_col, angle, radial), members in groups.items():
        if angle == 0.0 and radial == 0.0:
            _linear_blur_into(out, x, members, d_row, d_col, upper)
            continue
        part = x if len(groups) == 1 else x[members]
        if part.dtype == torch.uint8:
            mean = _general_blur(part.to(torch.float32), d_row, d_col, angle, radial).round_()
            blurred = mean.to(torch.int16).to(torch.uint8)  # float -> uint8 through int16: 3x faster
        else:
            blurred = _general_blur(part, d_row, d_col, angle, radial, upper)
        if len(groups) == 1:
            return blurred
        out[members] = blurred
    return out


def _blur_uint8(x: torch.Tensor, dx, dy, theta_deg, scale) -> torch.Tensor:
    """uint8 RGB: the blur on the 0-255 values themselves (int16 sums, exact), rounded once; no scaling to [0, 1]
    and back (the mean of in-range values needs no clamp)."""
    return ultrasound_blur_float(x, dx, dy, theta_deg, scale)


def ultrasound_blur(
    image: torch.Tensor,
    dx: float | torch.Tensor,
    dy: float | torch.Tensor,
    theta_deg: float | torch.Tensor = 0.0,
    scale: float | torch.Tensor = 0.0,
) -> torch.Tensor:
    """Ultrasound blur of ``image`` (uint8 or float [0, 1], ``(..., C, H, W)``, C in {1, 3, 4}).

    ``dx`` / ``dy``: horizontal / vertical displacement in pixels of *this* image; ``theta_deg``: rotation in
    degrees; ``scale``: radial part. Each a float or one value per image. Returns the input's shape, dtype, device.
    """
    check_image(image)
    if image.dtype == torch.uint8:
        x, alpha = to_rgb(image)
        return from_uint8_rgb(_blur_uint8(x, dx, dy, theta_deg, scale), alpha, image)
    x, alpha = to_float_rgb(image)
    return from_float_rgb(ultrasound_blur_float(x, dx, dy, theta_deg, scale), alpha, image)


class UltrasoundBlur(CameraAttack):
    """Ultrasound blur attack as a torchvision v2 transform.

    Intensity -> linear displacement ``d`` (pixels at 256x256): 0 / 5 (weak) / 10 (medium) / 20 (strong),
    piecewise linear; the paper blurs diagonally, ``dx = dy = d`` (scaled with the image width / height).
    Options: ``displacement_px`` fixes ``d``; ``random_direction=True`` turns the path to a random angle per
    sample (same length ``d * sqrt(2)``); ``rotation_deg`` and ``radial_scale`` add the paper's rotational and
    radial components, reached at intensity 1 and scaled linearly with the intensity (0 at s = 0). As
    ``lerobot-phantom-calibrate`` measures a camera: ``displacement_per_intensity_px=(dx, dy)`` is the measured
    blur, horizontal and vertical, at intensity 1 in pixels of the reference scale of the longer image side
    (``s * (dx, dy) * max(H, W) / 256`` at intensity ``s``; ``random_direction`` keeps its length and turns it),
    ``path="sinusoidal"`` centres the path on the pixel and dwells
    at its ends as a resonating gyroscope does (arcsine weights), and ``gamma`` (a power law) or ``shoulder`` /
    ``shoulder_exponent`` (a curve whose highlights roll off, ``physics.ShoulderCurve``) average the path in linear
    light rather than in pixel values; the paper's sweep (``path="uniform"``) runs one way from the pixel in either
    light (``physics.attack_blur_offsets``). With any of these the path is sampled continuously, as the calibration
    fits it (``measured_path``).
    """

    name: ClassVar[str] = "ultrasound_blur"
    _apply_in_unit_range: ClassVar[bool] = True  # _apply clamps chunk by chunk, in cache
    LEVEL_DISPLACEMENT_PX: ClassVar[tuple[float, float, float, float]] = LEVEL_DISPLACEMENT_PX
    # the authors' adversarial training: displacement randint(5, 20) px (both ends included) at the reference size
    random_parameter: ClassVar[RandomParameter] = RandomParameter(
        5, 20, integer=True, levels=LEVEL_DISPLACEMENT_PX
    )

    def __init__(
        self,
        intensity: IntensitySpec = "medium",
        *,
        displacement_px: float | None = None,
        displacement_per_intensity_px: Sequence[float] | None = None,
        random_direction: bool = False,
        rotation_deg: float = 0.0,
        radial_scale: float = 0.0,
        path: str = "uniform",
        gamma: float | None = None,
        shoulder: float | None = None,
        shoulder_exponent: float = 1.0,
        seed: int | None = None,
        generator: torch.Generator | None = None,
    ) -> None:
        super().__init__(intensity, seed=seed, generator=generator)
        # displacement_per_intensity_px / path="sinusoidal" / gamma / shoulder (lerobot-phantom-calibrate): the
        # measured blur; a resonating gyroscope's arcsine-weighted path centred on the pixel, optionally averaged in
        # linear light decoded by a power law or a shouldered tone curve (physics.line_blur, physics.ShoulderCurve)
        if path not in physics.BLUR_PATHS:
            raise ValueError(f"unknown blur path {path!r}; valid: {', '.join(physics.BLUR_PATHS)}")
        self.path = path
        self.tone = physics.tone_options(gamma, shoulder, shoulder_exponent, owner="UltrasoundBlur")
        for what, value in (("displacement_px", displacement_px), ("rotation_deg", rotation_deg)):
            if value is not None and not math.isfinite(float(value)):
                raise ValueError(f"{what} must be finite, got {value!r}")
        if not (0.0 <= float(radial_scale) <= 1.0):
            raise ValueError(f"radial_scale must lie in [0, 1], got {radial_scale!r}")
        self.displacement_px = None if displacement_px is None else float(displacement_px)
        self.displacement_per_intensity_px = _measured_displacement(displacement_per_intensity_px)
        if self.displacement_px is not None and self.displacement_per_intensity_px is not None:
            raise ValueError(
                "displacement_px (the paper's diagonal, fixed) and displacement_per_intensity_px (a measured blur, "
                "growing with the intensity) are alternatives: give one"
            )
        if self.measured_path and (float(rotation_deg) != 0.0 or float(radial_scale) != 0.0):
            raise ValueError(
                "displacement_per_intensity_px=, path='sinusoidal', gamma= and shoulder= model the linear blur only "
                "(rotation_deg = radial_scale = 0)"
            )
        self.random_direction = bool(random_direction)
        self.rotation_deg = float(rotation_deg)
        self.radial_scale = float(radial_scale)

    @property
    def measured_path(self) -> bool:
        """Whether the blur follows a calibrated camera (a measured displacement, path shape or tone curve): then
        the path is sampled continuously (``physics.line_blur``, bilinear taps), as the calibration fits it, not at
        the paper code's whole pixels (its ``int()`` shifts a sub-pixel path by up to a pixel towards the start)."""
        return (
            self.path != "uniform" or self.tone is not None or self.displacement_per_intensity_px is not None
        )

    def displacement_for(self, s: torch.Tensor) -> torch.Tensor:
        """Linear displacement per axis, pixels at the 256x256 reference, at intensity ``s`` (per sample)."""
        if self.displacement_px is not None:
            return torch.full_like(s, self.displacement_px, dtype=torch.float32)
        d = interpolate_levels(s, self.LEVEL_DISPLACEMENT_PX)
        # "random" draws whole pixels and reports s through the inverse level map; the float32 round trip comes
        # back a few 1e-6 px short of the integer, which would drop a sample from the path: snap it
        whole = d.round()
        return torch.where((d - whole).abs() < 1e-4, whole, d)

    def _sample(self, s, height, width, generator, device):
        s64 = s.to(torch.float64)
        if self.displacement_per_intensity_px is None:
            d = self.displacement_for(s).to(torch.float64)
            d_col, d_row = d, d
            column_scale, row_scale = width / REFERENCE_SIZE, height / REFERENCE_SIZE
        else:
            measured_col, measured_row = self.displacement_per_intensity_px
            d_col, d_row = measured_col * s64, measured_row * s64
            column_scale = row_scale = max(height, width) / REFERENCE_SIZE
        if self.random_direction:
            if generator is None:
                raise ValueError("random_direction=True needs a torch.Generator (pass generator= or seed=)")
            angle = torch.rand(s.shape[0], generator=generator, dtype=torch.float64, device=generator.device)
            angle = angle.to(s.device) * (2 * math.pi)
            length = torch.hypot(d_col, d_row)
            d_col, d_row = length * torch.cos(angle), length * torch.sin(angle)
        return {
            "dx": (d_col * column_scale).to(device),
            "dy": (d_row * row_scale).to(device),
            "theta_deg": (self.rotation_deg * s64).to(device),
            "scale": (self.radial_scale * s64).to(device),
        }

    def _apply(self, x: torch.Tensor, params: dict[str, torch.Tensor]) -> torch.Tensor:
        if self.measured_path:
            dx, dy = params["dx"].to(x.device, x.dtype), params["dy"].to(x.device, x.dtype)
            taps = physics.blur_taps(float(dx.abs().max()), float(dy.abs().max()))
            offsets = physics.attack_blur_offsets(self.path, taps, dtype=x.dtype, device=x.device)
            if self.tone is None:
                blurred = physics.line_blur(x, dx, dy, offsets)
            else:
                blurred = physics.encode(
                    physics.line_blur(physics.decode(x, self.tone), dx, dy, offsets), self.tone
                )
            still = ((dx == 0) & (dy == 0)).reshape(-1, 1, 1, 1)  # s = 0 is exactly the identity
            if bool(still.any()):
                blurred = torch.where(still, x, blurred)
            return blurred.clamp_(0.0, 1.0)
        return ultrasound_blur_float(
            x, params["dx"], params["dy"], params["theta_deg"], params["scale"], upper=1.0
        )

    def _apply_uint8(self, x: torch.Tensor, params: dict[str, torch.Tensor]) -> torch.Tensor:
        if self.measured_path:
            return NotImplemented
        return _blur_uint8(x, params["dx"], params["dy"], params["theta_deg"], params["scale"])

    def extra_repr(self) -> str:
        extra = [f"{k}={getattr(self, k)!r}" for k in ("displacement_px", "rotation_deg", "radial_scale")]
        if (
            self.displacement_per_intensity_px is not None
        ):  # absent otherwise: earlier sweeps' records stay valid
            extra.insert(1, f"displacement_per_intensity_px={self.displacement_per_intensity_px!r}")
        return ", ".join([super().extra_repr(), *extra, f"random_direction={self.random_direction}"])
