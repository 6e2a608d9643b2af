"""Light projection: a projector throws a fake image onto the scene or straight into the lens (paper: Method,
"Light Projection Attack"; Appendix A, Algorithm "Light Projection Attack").

Physics: the projected light replaces part of the scene's radiance where the image lands; the paper records the
projected image and composites it over the frame as a watermark. Algorithm: the watermark's alpha is scaled by
the transparency ``t`` (``int(a * t)`` on 8-bit alpha, as the paper's code), the watermark is placed centred plus
an offset, ``pos = ((W - w) // 2 + x_off, (H - h) // 2 + y_off)``, and alpha-composited:
``out = img * (1 - a t) + wm * a t``.

Levels (Table 2, "weight of pattern"): t = 0 / 0.1 / 0.5 / 0.9 at s = 0 / weak / medium / strong, linear in
between (``interpolate_levels``).

Pattern: a procedural, text-free shape (``patterns.PROJECTION_SHAPES``: ``can`` (default; the layout, size,
alpha coverage and colour of the authors' ``can.png`` watermark), ``stop_sign`` octagon, ``arrow``, ``disk``) or
``pattern=PATH`` for a user image (RGBA keeps its alpha; RGB is opaque). ``size="native"`` (default, the authors'
code) pastes the pattern at its own pixel size on every frame: an image keeps its pixels, a procedural shape is 50
pixels tall (the can 50x42, like ``can.png``), so it covers 2.3% of a 224x224 frame, 1.6% of 256x256 and 0.7% of
480x640, exactly as the authors' watermark would. ``size=FRACTION`` instead scales the watermark's longer side to
that fraction of the image's shorter side (aspect kept; images resized with PIL's LANCZOS filter), the same share
of every frame. Offsets ``x_offset``/``y_offset`` are pixels at
the 256x256 reference (``base.REFERENCE_SIZE``), scaled by ``W/256`` and ``H/256`` and rounded; the watermark may
hang over the border (clipped). ``position="random"`` draws both offsets per sample uniformly in
``[-max_offset, max_offset]`` (reference pixels) instead. Only ``t`` (via the intensity) and, when asked, the
offsets are random; the shape is fixed per instance.

Deviations from the paper's code: the watermark is built (or read) once and cached per size instead of being
loaded on every call; randomness comes from the attack's seeded ``torch.Generator``; compositing is done in float
(at most 1 grey level from PIL's integer ``paste``; with the authors' ``can.png`` the output is identical at all three
levels). The uint8 kernel copies the frame and blends only under the watermark.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import ClassVar

import torch

from lerobot_phantom.transforms import physics
from lerobot_phantom.transforms.base import (
    REFERENCE_SIZE,
    CameraAttack,
    check_image,
    from_float_rgb,
    to_float_rgb,
)
from lerobot_phantom.transforms.intensity import IntensitySpec, RandomParameter, interpolate_levels
from lerobot_phantom.transforms.patterns import (
    NATIVE_SHAPE_HEIGHT,
    PROJECTION_SHAPES,
    SHAPE_ASPECT,
    check_levels,
    fit_size,
    load_pattern_image,
    projection_shape,
    resize_pattern,
)

TRANSPARENCY_LEVELS: tuple[float, float, float, float] = (0.0, 0.1, 0.5, 0.9)
_ALPHA_EPS = 1e-4  # int(a * t) in float64 vs float32: keep exact products like 30 * 0.1 on the same side


def _scaled_alpha(alpha: torch.Tensor, transparency: torch.Tensor) -> torch.Tensor:
    """``int(a8 * t) / 255`` for 8-bit alpha ``a8``; ``transparency`` broadcasts from the left."""
    alpha8 = torch.round(alpha * 255.0)
    t = transparency.reshape(-1, *([1] * (alpha.ndim - 1))) if alpha.ndim > 1 else transparency
    return torch.floor(alpha8 * t + _ALPHA_EPS) / 255.0


def placement(
    height: int, width: int, pattern_height: int, pattern_width: int, offset: torch.Tensor
) -> tuple[torch.Tensor, torch.Tensor]:
    """Top-left (row, col) ``(B,)`` of the watermark for offsets ``(B, 2)`` = (x, y) reference pixels."""
    dx = torch.round(offset[:, 0] * (width / REFERENCE_SIZE)).long()
    dy = torch.round(offset[:, 1] * (height / REFERENCE_SIZE)).long()
    return (height - pattern_height) // 2 + dy, (width - pattern_width) // 2 + dx


def composite(
    x: torch.Tensor,
    pattern_rgba: torch.Tensor,
    transparency: torch.Tensor,
    top: torch.Tensor,
    left: torch.Tensor,
) -> torch.Tensor:
    """Alpha-composite ``pattern_rgba`` ``(4, h, w)`` onto float ``x`` ``(B, 3, H, W)`` at per-sample top-left."""
    batch, _, height, width = x.shape
    ph, pw = pattern_rgba.shape[-2:]
    t = transparency.to(x.device, torch.float32).reshape(-1).expand(batch)
    top, left = top.to(x.device).expand(batch), left.to(x.device).expand(batch)
    if bool((top == top[0]).all() and (left == left[0]).all()):
        r0, c0 = int(top[0]), int(left[0])
        rs, re = max(0, r0), min(height, r0 + ph)
        cs, ce = max(0, c0), min(width, c0 + pw)
        out = x.clone()
        if rs >= re or cs >= ce:
            return out
        piece = pattern_rgba[:, rs - r0 : re - r0, cs - c0 : ce - c0]
        a = _scaled_alpha(piece[3][None, None], t)  # (B, 1, h', w')
        out[:, :, rs:re, cs:ce] = torch.lerp(x[:, :, rs:re, cs:ce], piece[None, :3], a)
        return out
    rows = torch.arange(height, device=x.device)[None] - top[:, None]  # (B, H) watermark row
    cols = torch.arange(width, device=x.device)[None] - left[:, None]
    inside = ((rows >= 0) & (rows < ph))[:, :, None] & ((cols >= 0) & (cols < pw))[:, None, :]
    layer = pattern_rgba[
        :, rows.clamp(0, ph - 1)[:, :, None], cols.clamp(0, pw - 1)[:, None, :]
    ]  # (4, B, H, W)
    a = _scaled_alpha(layer[3] * inside, t)[:, None]
    return torch.lerp(x, layer[:3].permute(1, 0, 2, 3), a)


def light_projection(
    image: torch.Tensor,
    pattern_rgba: torch.Tensor,
    transparency: float | torch.Tensor,
    x_offset: int | torch.Tensor = 0,
    y_offset: int | torch.Tensor = 0,
) -> torch.Tensor:
    """Composite the watermark ``pattern_rgba`` (``(4, h, w)``, uint8 or float, used at its own size) onto ``image``.

    ``transparency`` in [0, 1] (float or one per sample); offsets in *image* pixels from the centred position
    (ints or one per sample), exactly Appendix A's algorithm. Returns the image's dtype, shape and device.
    """
    check_image(image)
    if pattern_rgba.ndim != 3 or pattern_rgba.shape[0] != 4 or pattern_rgba.numel() == 0:
        raise ValueError(
            f"pattern_rgba must be a non-empty (4, h, w) RGBA tensor, got {tuple(pattern_rgba.shape)}"
        )
    t = torch.as_tensor(transparency, dtype=torch.float32).reshape(-1)
    if not bool(((t >= 0) & (t <= 1)).all()):
        raise ValueError(f"transparency must lie in [0, 1], got {transparency!r}")
    x, keep_alpha = to_float_rgb(image)
    pattern = pattern_rgba.to(x.device)
    pattern = pattern.to(torch.float32) / 255.0 if pattern.dtype == torch.uint8 else pattern.to(torch.float32)
    height, width = x.shape[-2:]
    ph, pw = pattern.shape[-2:]
    dx = torch.as_tensor(x_offset, device=x.device).reshape(-1).long()
    dy = torch.as_tensor(y_offset, device=x.device).reshape(-1).long()
    top, left = (height - ph) // 2 + dy, (width - pw) // 2 + dx
    y = composite(x, pattern, t, top, left)
    return from_float_rgb(y, keep_alpha, image)


class LightProjection(CameraAttack):
    """Light projection; see the module docstring. ``levels`` overrides the transparency table."""

    name: ClassVar[str] = "light_projection"
    # the authors' adversarial training: weight uniform in [0.1, 0.9] per attacked sample
    random_parameter: ClassVar[RandomParameter] = RandomParameter(0.1, 0.9)

    def __init__(
        self,
        intensity: IntensitySpec = "medium",
        *,
        pattern: str | Path = "can",
        size: float | str | None = "native",
        x_offset: float = 0.0,
        y_offset: float = 0.0,
        position: str = "fixed",
        max_offset: float = 96.0,
        levels: Sequence[float] = TRANSPARENCY_LEVELS,
        model: str = "paper",
        strength: float = 1.0,
        albedo: bool = False,
        reflectance_floor: float = 0.0,
        crosstalk: Sequence[Sequence[float]] | None = None,
        white: float = 1.0,
        gamma: float | None = 1.0,
        shoulder: float | None = None,
        shoulder_exponent: float = 1.0,
        projector_gamma: float | None = None,
        spread: float = 0.0,
        colour_correction: Sequence[float] | None = None,
        seed: int | None = None,
        generator: torch.Generator | None = None,
    ) -> None:
        super().__init__(intensity, seed=seed, generator=generator)
        self.levels = check_levels(levels, "light projection transparency", upper=1.0)
        # model="additive"/"blend" (lerobot-phantom-calibrate): projector light at strength x intensity through
        # physics.project_light (albedo, 3x3 cross-talk, white level, tone curve -- a power law or one with a
        # highlight shoulder, physics.ShoulderCurve --, the projector's own display transfer, spread over ``spread``
        # pixels at the 256-pixel reference, scaled by max(H, W) / 256; with ``colour_correction``, 9 numbers whose
        # rows sum to 1, the light meets the reflectance and the clip in the camera's raw channels, which that matrix
        # then mixes)
        if model not in ("paper", "additive", "blend"):
            raise ValueError(f"unknown light projection model {model!r}; valid: 'paper', 'additive', 'blend'")
        if spread < 0.0 or (spread > 0.0 and model == "paper"):
            raise ValueError(
                f"spread={spread!r}: the projected light's spread is >= 0 reference pixels and only spreads light "
                "in the physical models (model='additive' or 'blend'); the paper's watermark has sharp edges"
            )
        if projector_gamma is not None and (projector_gamma <= 0.0 or model == "paper"):
            raise ValueError(
                f"projector_gamma={projector_gamma!r}: the projector's display exponent is > 0 and only turns the "
                "pattern into light in the physical models (model='additive' or 'blend'); None decodes the "
                "pattern with the camera's gamma"
            )
        if shoulder is not None and model == "paper":
            raise ValueError(
                f"shoulder={shoulder!r} bends the tone curve the physical models (model='additive' or 'blend') "
                "compose light in; the paper's watermark blends the encoded values"
            )
        correction = physics.check_colour_correction(colour_correction, "LightProjection")
        if correction is not None and model != "additive":
            raise ValueError(
                f"colour_correction mixes the raw channels the projected light adds in: model='additive', not "
                f"{model!r}"
            )
        # kept as fitted: the light model casts it to each image's dtype
        matrix = None if crosstalk is None else torch.tensor(crosstalk, dtype=torch.float64)
        if matrix is not None and matrix.shape != (3, 3):
            raise ValueError(f"crosstalk must be a 3x3 matrix, got shape {tuple(matrix.shape)}")
        self.model = model
        self.physical = {
            "strength": float(strength),
            "albedo": bool(albedo),
            "reflectance_floor": float(reflectance_floor),
            "crosstalk": matrix,
            "white": float(white),
            "tone": physics.tone_options(
                None if gamma is None else float(gamma), shoulder, shoulder_exponent, owner="LightProjection"
            ),
            "projector_gamma": None if projector_gamma is None else float(projector_gamma),
            "spread": float(spread),
            "colour_correction": None
            if correction is None
            else torch.tensor(correction, dtype=torch.float64).reshape(3, 3),
        }
        if size is None or size == "native":
            size = None
        elif isinstance(size, str) or not (0.0 < float(size) <= 4.0):
            raise ValueError(
                f"size must be 'native' (the pattern's own pixel size) or the watermark's longer side / the "
                f"image's shorter side in (0, 4], got {size!r}"
            )
        if position not in ("fixed", "random"):
            raise ValueError(
                f"unknown position {position!r}; valid: 'fixed' (x_offset, y_offset) or 'random'"
            )
        if max_offset < 0:
            raise ValueError(f"max_offset must be >= 0, got {max_offset}")
        self.size = None if size is None else float(size)
        self.offset = (float(x_offset), float(y_offset))
        self.position = position
        self.max_offset = float(max_offset)
        pattern_text = str(pattern)
        if pattern_text in PROJECTION_SHAPES:
            self.pattern = pattern_text
            self._user_pattern = None
        elif isinstance(pattern, Path) or Path(pattern_text).suffix:
            self.pattern = pattern_text
            # Loaded once here (not on every call, the paper code's defect); travels with the pickle.
            self._user_pattern = load_pattern_image(pattern_text, keep_alpha=True)
        else:
            raise ValueError(
                f"unknown projection pattern {pattern!r}; valid: {', '.join(PROJECTION_SHAPES)} or an image path"
            )

    def _sample(
        self,
        s: torch.Tensor,
        height: int,
        width: int,
        generator: torch.Generator | None,
        device: torch.device | str | None,
    ) -> dict[str, torch.Tensor]:
        batch = s.shape[0]
        if self.position == "random":
            if generator is None:
                raise ValueError("position='random' needs a torch.Generator (pass generator= or seed=)")
            u = torch.rand(batch, 2, generator=generator, device=generator.device)
            offset = ((2.0 * u - 1.0) * self.max_offset).to(device)
        else:
            offset = torch.tensor(self.offset, dtype=torch.float32, device=device).expand(batch, 2).clone()
        return {"transparency": interpolate_levels(s, self.levels), "offset": offset}

    def watermark(self, height: int, width: int, device: torch.device | str | None = None) -> torch.Tensor:
        """The RGBA watermark ``(4, h, w)`` for an image of this size (on the 8-bit grid); cached.

        ``size="native"``: an image keeps its own pixels on every frame, a procedural shape is
        ``patterns.NATIVE_SHAPE_HEIGHT`` (50) pixels tall, the height of the authors' ``can.png``.
        """
        box = None if self.size is None else max(1, round(self.size * min(height, width)))

        def make() -> torch.Tensor:
            if self._user_pattern is None:
                shape_box = NATIVE_SHAPE_HEIGHT if box is None else box
                if box is not None and SHAPE_ASPECT.get(self.pattern, 1.0) > 1.0:
                    shape_box = max(1, round(box / SHAPE_ASPECT[self.pattern]))  # the longer side is the box
                return projection_shape(self.pattern, shape_box).to(device)
            if box is None:
                return self._user_pattern.to(device)
            return resize_pattern(self._user_pattern, *fit_size(*self._user_pattern.shape[-2:], box)).to(
                device
            )

        # contiguous CHW: a channels-last pattern (an image's HWC pixels) makes every broadcast blend 10x slower
        return self._cached((box, str(device)), lambda: make().contiguous())

    def _apply(self, x: torch.Tensor, params: dict[str, torch.Tensor]) -> torch.Tensor:
        height, width = x.shape[-2:]
        rgba = self.watermark(height, width, x.device)
        top, left = placement(height, width, rgba.shape[-2], rgba.shape[-1], params["offset"].to(x.device))
        if self.model != "paper":
            projected = composite(
                torch.zeros_like(x), rgba, torch.ones_like(params["transparency"]), top, left
            )
            return self.project(x, projected, params["intensity"].to(x.device))
        return composite(x, rgba, params["transparency"], top, left)

    def project(self, x: torch.Tensor, projected: torch.Tensor, intensity: torch.Tensor) -> torch.Tensor:
        """The physical models' light (``model`` 'additive' or 'blend'): the projector sent ``projected``
        (``(B, 3, H, W)``, black where it sends nothing) at ``intensity`` per sample, onto the scene ``x``."""
        if self.model == "paper":
            raise ValueError("project() is the physical models' light; the paper's watermark is a composite")
        p = self.physical
        return physics.project_light(
            x,
            projected,
            intensity * p["strength"],
            albedo=p["albedo"],
            reflectance_floor=p["reflectance_floor"],
            crosstalk=p["crosstalk"],
            white=p["white"],
            gamma=p["tone"],
            projector_gamma=p["projector_gamma"],
            spread_px=p["spread"] * max(x.shape[-2:]) / REFERENCE_SIZE,
            blend=self.model == "blend",
            colour_correction=p["colour_correction"],
        )

    def _apply_uint8(self, x: torch.Tensor, params: dict[str, torch.Tensor]) -> torch.Tensor:
        """The paper's composite on uint8 ``(N, 3, H, W)``: a copy of the frame, blended only under the watermark.

        Only the watermark's pixels (2.3% of a 224x224 frame by default) are blended, in int16 with PIL's integer
        ``paste`` formula (``_composite_uint8``), which equals the float path's rounded blend. Placement and a
        shared weight cost no tensor op per call (cached per level).
        """
        if self.model != "paper":
            return NotImplemented
        batch, _, height, width = x.shape
        rgba = self.watermark(height, width, x.device)
        offsets = params["offset"].reshape(-1, 2).tolist()
        weights = params["transparency"].reshape(-1).tolist()
        out = x.clone(memory_format=torch.contiguous_format)
        groups: dict[tuple[float, float], list[int]] = {}
        for i in range(batch):
            groups.setdefault(tuple(offsets[i if len(offsets) > 1 else 0]), []).append(i)
        for (x_off, y_off), members in groups.items():
            top = (height - rgba.shape[-2]) // 2 + round(y_off * (height / REFERENCE_SIZE))
            left = (width - rgba.shape[-1]) // 2 + round(x_off * (width / REFERENCE_SIZE))
            window = self._cached(
                ("window", rgba.shape, top, left, height, width, str(x.device)),
                lambda top=top, left=left: _integer_window(rgba, top, left, height, width),
            )
            if window is None:
                continue
            mine = [weights[i if len(weights) > 1 else 0] for i in members]
            if len(set(mine)) == 1:  # one weight (a level): the blend weights are cached
                key = ("weights", rgba.shape, top, left, height, width, mine[0], str(x.device))
                blend = self._cached(key, lambda w=mine[0], win=window: _integer_weights(win, [w], x.device))
            else:
                blend = _integer_weights(window, mine, x.device)
            contiguous = members[-1] - members[0] == len(members) - 1
            if contiguous:
                _composite_uint8(out[members[0] : members[-1] + 1], window[0], blend)
            else:
                for j, i in enumerate(members):
                    single = tuple(w[j : j + 1] if w.shape[0] > 1 else w for w in blend)
                    _composite_uint8(out[i : i + 1], window[0], single)
        return out

    def extra_repr(self) -> str:
        return (
            f"{super().extra_repr()}, pattern={self.pattern!r}, size={self.size or 'native'!r}, "
            f"position={self.position!r}"
        )


def _integer_window(
    rgba: torch.Tensor, top: int, left: int, height: int, width: int
) -> tuple[tuple[slice, slice], torch.Tensor, torch.Tensor] | None:
    """The watermark's visible window in the frame, its 8-bit alpha ``(1, 1, h', w')`` (float32, whole numbers)
    and its colour ``(1, 3, h', w')`` (int16, 0-255); None when the watermark misses the frame."""
    ph, pw = rgba.shape[-2:]
    rs, re, cs, ce = max(0, top), min(height, top + ph), max(0, left), min(width, left + pw)
    if rs >= re or cs >= ce:
        return None
    piece = rgba[:, rs - top : re - top, cs - left : ce - left]
    alpha8 = torch.round(piece[3][None, None] * 255.0).contiguous()
    colour = torch.round(piece[None, :3] * 255.0).to(torch.int16).contiguous()
    return (slice(rs, re), slice(cs, ce)), alpha8, colour


def _integer_weights(
    window: tuple[tuple[slice, slice], torch.Tensor, torch.Tensor],
    transparency: list[float],
    device: torch.device,
) -> tuple[torch.Tensor, torch.Tensor]:
    """PIL's integer blend weights for per-sample ``transparency``: ``255 - m`` ``(B, 1, h', w')`` and
    ``wm * m + 128`` ``(B, 3, h', w')`` in int16 (wrapping past 32767: the blend is taken modulo 2^16), with
    ``m = int(a8 * t)`` as ``_scaled_alpha``."""
    _, alpha8, colour = window
    t = torch.tensor(transparency, dtype=torch.float32, device=device).reshape(-1, 1, 1, 1)
    m = torch.floor_(alpha8 * t + _ALPHA_EPS).to(torch.int16)
    return 255 - m, colour * m + 128


def _composite_uint8(
    out: torch.Tensor, window: tuple[slice, slice], weights: tuple[torch.Tensor, torch.Tensor]
) -> None:
    """``composite`` in place on uint8 ``out`` ``(B, 3, H, W)``: PIL's ``paste`` formula
    ``v = x (255 - m) + wm m + 128``, ``out = (v + (v >> 8)) >> 8`` (= round(v / 255), no ties since 255 is odd),
    in int16 arithmetic modulo 2^16 (v < 65536; the logical shift is an arithmetic one masked to 8 bits, and the
    final cast to uint8 keeps the low byte)."""
    keep, offset = weights
    region = out[:, :, window[0], window[1]]
    v = region.to(torch.int16).mul_(keep).add_(offset)
    v.add_(torch.bitwise_right_shift(v, 8).bitwise_and_(255)).bitwise_right_shift_(8)
    region.copy_(v)
