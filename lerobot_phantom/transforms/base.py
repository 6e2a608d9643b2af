"""The base class of every camera attack: a torchvision v2 ``Transform`` with explicit, seeded randomness.

Contract (every attack in this package, and the mixer, eval and device-side step rely on it):

* ``attack(img)`` - the torchvision path. ``make_params`` draws one parameter set per sample of the batch from
  the attack's own ``torch.Generator`` (seeded from ``seed`` and the dataloader worker id, never the global RNG);
  ``transform`` applies them.
* ``attack.sample_params(batch_size, height, width, intensity=..., generator=..., device=...)`` - explicit
  parameter draw (each value is a tensor with leading dim ``batch_size``, always including ``"intensity"``).
* ``attack.apply_params(img, params)`` - deterministic application. A leading dim of 1 in ``params`` broadcasts
  over the whole batch, which is how one sample's frames (``delta_timestamps``) share one attack.

Images: uint8 (0-255) or floating (0-1) tensors, ``(C, H, W)`` or ``(B, C, H, W)`` (any further leading dims are
flattened into the batch), C in {1, 3, 4}; output has the input's dtype, shape and device. Subclasses implement
``_sample(s, height, width, generator, device)`` and ``_apply(x, params)`` on float32 ``(B, 3, H, W)`` in [0, 1],
and optionally ``_apply_uint8(x, params)`` on uint8 ``(B, 3, H, W)``, which uint8 images then take with no float
round trip (contract: ``CameraAttack._apply_uint8``).
"""

from __future__ import annotations

import hashlib
from collections.abc import Callable
from typing import Any, ClassVar

import torch
from torch.utils.data import get_worker_info
from torchvision import tv_tensors
from torchvision.transforms import v2
from torchvision.transforms.v2.functional import is_pure_tensor

from lerobot_phantom.transforms.intensity import (
    IntensitySpec,
    is_random,
    parse_intensity,
    sample_intensity,
    sample_random_intensity,
)

REFERENCE_SIZE = 256
"""Pixel-sized parameters (blur displacement, pattern offsets) are defined on a 256x256 image and scale with size."""

SUPPORTED_CHANNELS = (1, 3, 4)

MAX_CACHED = 8
"""Derived tensors (patterns, profiles) kept per attack instance, one per image size and device."""


def derive_seed(*parts: int | str) -> int:
    """A 63-bit seed from any tuple of ints/strings, stable across processes and Python versions."""
    digest = hashlib.blake2b(repr(parts).encode(), digest_size=8).digest()
    return int.from_bytes(digest, "little") & ((1 << 63) - 1)


def check_image(img: torch.Tensor) -> None:
    if not isinstance(img, torch.Tensor):
        raise TypeError(f"expected a torch.Tensor image, got {type(img).__name__}")
    if img.ndim < 3:
        raise ValueError(
            f"expected an image of shape (C, H, W) or (B, C, H, W), got shape {tuple(img.shape)}"
        )
    if img.shape[-3] not in SUPPORTED_CHANNELS:
        raise ValueError(
            f"expected {SUPPORTED_CHANNELS} channels in dim -3 (CHW layout), got shape {tuple(img.shape)}"
        )
    if img.numel() == 0:
        raise ValueError(f"empty image of shape {tuple(img.shape)}")
    if img.dtype == torch.bool or img.is_complex():
        raise TypeError(f"unsupported image dtype {img.dtype}; use uint8 (0-255) or float (0-1)")
    if img.is_floating_point():
        # A sum propagates NaN and +-inf at a quarter of the cost of aminmax (which costs as much as a clone);
        # only a non-finite sum (which a huge but finite image can also give) needs the exact check.
        total = img.sum(dtype=torch.float64 if img.dtype == torch.float64 else torch.float32)
        if not torch.isfinite(total):
            low, high = img.aminmax()
            if not (torch.isfinite(low) and torch.isfinite(high)):
                raise ValueError("image contains NaN or infinite values")


def per_sample_values(
    value: float | torch.Tensor, batch: int, device: torch.device, what: str
) -> torch.Tensor:
    """A scalar or a ``(batch,)`` / ``(1,)`` tensor -> float64 ``(batch,)`` on ``device``."""
    t = torch.as_tensor(value, dtype=torch.float64).to(device).reshape(-1)
    if t.numel() == 1:
        return t.expand(batch)
    if t.numel() != batch:
        raise ValueError(
            f"{what} must be a scalar or have one value per sample ({batch}), got {t.numel()} values"
        )
    return t


def to_float_rgb(img: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor | None]:
    """Any supported image -> (float32 (N, 3, H, W) in [0, 1], alpha channel or None)."""
    x = img.reshape(-1, *img.shape[-3:])
    # uint8 -> float makes a fresh tensor, so scaling it in place saves one full-size allocation
    x = x.to(torch.float32).div_(255.0) if x.dtype == torch.uint8 else x.to(torch.float32)
    alpha = None
    if x.shape[1] == 4:
        x, alpha = x[:, :3], x[:, 3:]
    elif x.shape[1] == 1:
        x = x.expand(-1, 3, -1, -1)
    return x, alpha


def to_rgb(img: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor | None]:
    """Any supported image -> ((N, 3, H, W) RGB in the image's own dtype, alpha channel or None).

    Views of ``img`` where possible (an alpha split, a grey image expanded to three channels): read-only inputs.
    """
    x = img.reshape(-1, *img.shape[-3:])
    if x.shape[1] == 4:
        return x[:, :3], x[:, 3:]
    if x.shape[1] == 1:
        return x.expand(-1, 3, -1, -1), None
    return x, None


def from_uint8_rgb(x: torch.Tensor, alpha: torch.Tensor | None, like: torch.Tensor) -> torch.Tensor:
    """Inverse of ``to_rgb`` for a uint8 result: back to the channel count and shape of ``like`` (uint8).

    A grey image gets the rounded channel mean, as ``from_float_rgb`` gives it (the mean of three integers is never
    exactly half-way, so round-half-up in integers equals torch's round-half-even). The result never aliases
    ``like``.
    """
    if like.shape[-3] == 1:
        total = x.sum(dim=1, keepdim=True, dtype=torch.int16)
        x = total.mul_(2).add_(3).div_(6, rounding_mode="floor").to(torch.uint8)
    elif alpha is not None:
        x = torch.cat([x, alpha], dim=1)
    elif _shares_storage(x, like):
        x = x.clone()
    return x.reshape(like.shape)


def _shares_storage(a: torch.Tensor, b: torch.Tensor) -> bool:
    return a.untyped_storage().data_ptr() == b.untyped_storage().data_ptr()


def from_float_rgb(
    x: torch.Tensor, alpha: torch.Tensor | None, like: torch.Tensor, *, in_unit_range: bool = False
) -> torch.Tensor:
    """Inverse of ``to_float_rgb``: back to the dtype, channel count and shape of ``like``.

    ``in_unit_range``: ``x`` is a fresh tensor (no view of ``like``) already in [0, 1], so the clamp (a full pass)
    is skipped."""
    if like.shape[-3] == 1:
        x = x.mean(dim=1, keepdim=True)
    elif alpha is not None:
        x = torch.cat([x, alpha], dim=1)
    # In place when the kernel's result is its own tensor; a result that aliases the caller's float input
    # (an identity, a view) must not be modified, so it gets one copy.
    if _shares_storage(x, like):
        x = x.clamp(0.0, 1.0)
    elif not in_unit_range or alpha is not None:  # the caller's alpha channel is not the kernel's
        x = x.clamp_(0.0, 1.0)
    if like.dtype == torch.uint8:
        # values are 0..255 here: float -> int16 -> uint8 is 3x faster than a direct float -> uint8 cast on the CPU
        x = x.mul_(255.0).round_().to(torch.int16).to(torch.uint8)
    else:
        x = x.to(like.dtype)
    return x.reshape(like.shape)


IMAGE_TYPES = (tv_tensors.Image, tv_tensors.Video, is_pure_tensor)
"""What a camera attack transforms in a torchvision v2 call (``check_type`` accepts the predicate)."""


def first_image(flat_inputs: list[Any]) -> torch.Tensor | None:
    """The input a v2 call's parameters are drawn for: its first image, video or plain tensor (None: nothing to
    attack, e.g. a call with masks only, which then passes through like any torchvision transform's)."""
    for x in flat_inputs:
        if isinstance(x, tv_tensors.Image | tv_tensors.Video) or is_pure_tensor(x):
            return x
    return None


def rewrap(output: torch.Tensor, inpt: Any) -> Any:
    """``output`` as ``inpt``'s tv_tensor type (Image stays Image, Video stays Video), plain tensors as they are."""
    return tv_tensors.wrap(output, like=inpt) if isinstance(inpt, tv_tensors.TVTensor) else output


class SeededAttack:
    """What every attack shares: its intensity, a seeded random stream, a per-instance cache, pickling.

    Streams follow the contract of torchvision and LeRobot, whose transforms draw from torch's global RNG, which a
    ``DataLoader`` reseeds in every worker with ``base_seed + worker_id`` (``base_seed`` is drawn from the main
    process's RNG, or the loader's ``generator``, each time an iterator is made):

    * in the main process (no dataloader worker) the stream is ``torch.Generator`` seeded from (attack name,
      ``seed``), or the ``generator`` the caller passed, used as is;
    * in a dataloader worker it is seeded from (attack name, ``seed``, the worker's seed
      ``get_worker_info().seed``, and the passed generator's ``initial_seed()`` if any): every worker gets its own
      stream, non-persistent workers get a new one every epoch (persistent workers continue theirs), and a fixed
      torch seed (LeRobot's ``--seed``) reproduces a run.

    The stream is keyed by the process's worker seed, so whatever the attack drew before it reached a worker (a
    preview in the main process, forked or pickled state) never leaks into the worker's stream. Pickling keeps the
    stream (a copy in the same process continues it) and drops the cache (derived tensors, rebuilt on demand).
    """

    name: ClassVar[str] = ""

    def _init_attack(
        self, intensity: IntensitySpec, seed: int | None, generator: torch.Generator | None
    ) -> None:
        self.intensity = intensity
        self.intensity_range = parse_intensity(intensity)
        self.seed = seed
        self._generator = generator
        self._stream_key: int | None = None  # the worker seed the generator belongs to (None: main process)
        self._user_seed = None if generator is None else generator.initial_seed()
        self._cache: dict[Any, Any] = {}

    def _get_generator(self) -> torch.Generator:
        """The stream of this process: see the class docstring."""
        worker = get_worker_info()
        key = None if worker is None else int(worker.seed)
        if self._generator is None or self._stream_key != key:
            seed = 0 if self.seed is None else self.seed
            if key is None:
                # only reached without a caller's generator: a caller's generator is kept in the main process
                derived = derive_seed(self.name, seed, -1)
            else:
                derived = derive_seed(
                    self.name, seed, "worker", key, -1 if self._user_seed is None else self._user_seed
                )
            self._generator = torch.Generator().manual_seed(derived)
            self._stream_key = key
        return self._generator

    def _cached(self, key: Any, make: Callable[[], Any]) -> Any:
        """``make()`` once per key (image size, device, ...); the oldest entry goes past ``MAX_CACHED``."""
        if key not in self._cache:
            if len(self._cache) >= MAX_CACHED:
                self._cache.pop(next(iter(self._cache)))
            self._cache[key] = make()
        return self._cache[key]

    def _intensities(
        self,
        batch_size: int,
        intensity: IntensitySpec | torch.Tensor | None,
        generator: torch.Generator | None,
        device: torch.device | str | None = None,
    ) -> torch.Tensor:
        """Per-sample intensities ``(batch_size,)``: the attack's own, a spec, or an explicit tensor."""
        if isinstance(intensity, torch.Tensor):
            s = intensity.to(device=device, dtype=torch.float32).reshape(-1).expand(batch_size).clone()
            if not bool(((s >= 0) & (s <= 1)).all()):
                raise ValueError(f"intensity must lie in [0, 1], got {s.tolist()}")
            return s
        if is_random(self.intensity if intensity is None else intensity):  # the authors' AT distribution
            return sample_random_intensity(self, batch_size, generator, device)
        rng = self.intensity_range if intensity is None else parse_intensity(intensity)
        return sample_intensity(rng, batch_size, generator, device)

    def __getstate__(self) -> dict[str, Any]:
        state = self.__dict__.copy()
        generator = state.pop("_generator", None)
        state["_generator_state"] = None if generator is None else generator.get_state()
        state["_cache"] = {}
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        generator_state = state.pop("_generator_state", None)
        state.setdefault("_stream_key", None)
        state.setdefault("_user_seed", None)
        self.__dict__.update(state)
        self._generator = None
        if generator_state is not None:
            # Continued only in the process it belongs to: _get_generator reseeds when the worker seed differs.
            self._generator = torch.Generator()
            self._generator.set_state(generator_state)


class CameraAttack(SeededAttack, v2.Transform):
    """Base class; see the module docstring for the contract."""

    # torchvision v2 semantics: images, videos and plain tensors are attacked; masks, boxes, keypoints and any other
    # tv_tensor (or non-tensor) pass through untouched.
    _transformed_types = IMAGE_TYPES
    _apply_in_unit_range: ClassVar[bool] = False
    """A subclass whose ``_apply`` always returns a fresh tensor in [0, 1] sets this: the final clamp is skipped."""

    def __init__(
        self,
        intensity: IntensitySpec = "medium",
        *,
        seed: int | None = None,
        generator: torch.Generator | None = None,
    ) -> None:
        super().__init__()
        self._init_attack(intensity, seed, generator)

    # -- torchvision v2 hooks -------------------------------------------------------------------------
    def make_params(self, flat_inputs: list[Any]) -> dict[str, Any]:
        image = first_image(flat_inputs)
        if image is None:
            return {}
        if image.ndim < 3:  # the full check runs once, in apply_params
            check_image(image)
        batch = int(torch.tensor(image.shape[:-3]).prod().item()) if image.ndim > 3 else 1
        height, width = image.shape[-2:]
        return self.sample_params(batch, height, width, generator=self._get_generator(), device=image.device)

    def transform(self, inpt: Any, params: dict[str, Any]) -> Any:
        return rewrap(self.apply_params(inpt.as_subclass(torch.Tensor), params), inpt)

    # -- explicit API -----------------------------------------------------------------------------------
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
        """Draw ``batch_size`` parameter sets. ``intensity`` overrides the attack's own (a tensor: per sample)."""
        s = self._intensities(batch_size, intensity, generator, device)
        params = self._sample(s, int(height), int(width), generator, device)
        params["intensity"] = s
        return params

    def apply_params(self, img: torch.Tensor, params: dict[str, torch.Tensor]) -> torch.Tensor:
        check_image(img)
        if img.dtype == torch.uint8:  # the subclass's integer kernel, if it has one for these parameters
            x, alpha = to_rgb(img)
            y = self._run_kernel(self._apply_uint8, x, params, img)
            if y is not NotImplemented:
                return from_uint8_rgb(y, alpha, img)
        x, alpha = to_float_rgb(img)
        y = self._run_kernel(self._apply, x, params, img)
        return from_float_rgb(y, alpha, img, in_unit_range=self._apply_in_unit_range)

    def _run_kernel(
        self, kernel: Callable[..., Any], x: torch.Tensor, params: dict[str, torch.Tensor], img: torch.Tensor
    ) -> Any:
        try:
            return kernel(x, params)
        except Exception as err:  # re-raised with context: which attack, which parameters
            shown = {
                k: (v.tolist() if isinstance(v, torch.Tensor) and v.numel() <= 8 else v)
                for k, v in params.items()
            }
            raise RuntimeError(
                f"{type(self).__name__} failed on image {tuple(img.shape)} with {shown}"
            ) from err

    # -- subclass hooks -----------------------------------------------------------------------------------
    def _sample(
        self,
        s: torch.Tensor,
        height: int,
        width: int,
        generator: torch.Generator | None,
        device: torch.device | str | None,
    ) -> dict[str, torch.Tensor]:
        raise NotImplementedError

    def _apply(self, x: torch.Tensor, params: dict[str, torch.Tensor]) -> torch.Tensor:
        raise NotImplementedError

    def _apply_uint8(self, x: torch.Tensor, params: dict[str, torch.Tensor]) -> Any:
        """Optional integer kernel: uint8 ``(N, 3, H, W)`` RGB (possibly a read-only view of the caller's image) ->
        uint8 ``(N, 3, H, W)``, within one grey level of ``_apply`` on ``x / 255``. ``NotImplemented`` (the
        default, or for parameters/options the integer kernel does not cover) falls back to the float path."""
        return NotImplemented

    def extra_repr(self) -> str:
        return f"intensity={self.intensity!r}, seed={self.seed!r}"
