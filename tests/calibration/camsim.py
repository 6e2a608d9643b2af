"""Ground-truth camera simulator for the calibration tests, written without looking at ``lerobot_phantom``.

The calibration library models each attack with its own equations; tests that render their data with those same
equations only show that a fit recovers its own parameters. This module renders frames with different functional
forms, chosen from camera physics rather than from the library:

* scene: procedural reflectance maps (rectangles, discs, gratings) under a smoothly varying, tinted illumination;
* optics: a two-Gaussian point spread function (core + wide scatter), optional lens vignetting;
* exposure: fixed, or auto-exposure that meters the clipped linear frame (centre-weighted) and solves for the
  exposure that brings it to a target grey, so a bright light source in view darkens the rest of the scene;
* sensor: RGGB Bayer mosaic, Poisson photon shot noise, Gaussian read noise, full-well clipping in linear
  electrons, 12-bit ADC (optionally with headroom above the full well, so a saturated pixel is written below the
  file's maximum);
* ISP: bilinear demosaic, a tone curve (sRGB transfer function, a filmic ACES-like curve, or a pure power law),
  8-bit quantisation and a JPEG round trip (PIL) at a given quality.

Each of the six camera attacks of the paper (Phantom Menace, Method and Appendix A) is rendered physically:

* laser blinding: laser irradiance (a Gaussian-mixture spot, optionally with a power-law glare tail) is added to the
  scene's irradiance before the sensor, saturates the well, and is metered by auto-exposure;
* light projection: projector light (projector gamma, a 3x3 camera response to the projector primaries) adds to the
  ambient light *before* reflection, so what the camera sees is scaled by the surface reflectance;
* laser colour strip: a rolling shutter integrates a pulsed laser; each row's energy is the overlap of its exposure
  window with the pulse train, whose phase is random per frame;
* EM colour strip: lines lost on the bus shift the raw Bayer rows by one, so the ISP demosaics them with the wrong
  colour-filter phase: in bands (a second lost line restores the phase) or from one row to the frame's end;
* EM truncation: a corrupted buffer address drops a band of rows and stitches rows from the frame's end below;
* ultrasound blur: the image moves along a path during the exposure, averaged in linear irradiance (a resonance
  whose dwell time is arcsine-distributed, or a triangle wave's constant-speed sweep) or in output space (the paper's
  linear and rotational forms); or the lens is defocused instead (a disc, in linear irradiance).

The paper's own digital forms (alpha blends, the fixed colour map, the fixed Gaussian band) are also here, written
from Appendix A, to render the *null* cases where the library's base model is the truth.
"""

from __future__ import annotations

import io
from dataclasses import dataclass, field, replace

import numpy as np
from PIL import Image
from scipy import ndimage

LUMA = np.array([0.2126, 0.7152, 0.0722])
TONE_CURVES = ("srgb", "filmic", "power")


@dataclass(frozen=True)
class Camera:
    height: int = 48
    width: int = 64
    # electrons at saturation; small wells make photon shot noise large
    full_well_e: float = 20000.0
    # the full well's signal as a share of the ADC's maximum code. Raw white levels of real sensors sit below the
    # ADC's maximum (headroom for offsets and gain spread, ISO-dependent digital gain), and an ISP that scales by
    # the ADC's range rather than by the white level writes a saturated pixel below the file's maximum, at
    # tone(well_share_of_adc): a clip the data can show, unlike saturation at the file's maximum, which no
    # frame can tell apart from the file's own range
    well_share_of_adc: float = 1.0
    read_noise_e: float = 3.0
    adc_bits: int = 12
    psf_sigma_px: float = 0.5
    psf_wide_sigma_px: float = 3.0
    psf_wide_share: float = 0.03
    tone: str = "srgb"
    # only for tone == "power": output = linear ** (1 / tone_gamma)
    tone_gamma: float = 2.2
    jpeg_quality: int = 93
    auto_exposure: bool = False
    # mean clipped linear luminance the exposure (auto or fixed from the clean scene) aims at
    exposure_target: float = 0.18
    # relative loss of light at the image corner (cos^4-like), an effect the calibration library has no name for
    vignetting: float = 0.0
    # the ISP's colour correction matrix (row-major 3x3, rows summing to 1 so white stays white), applied to the
    # demosaiced linear frame: camera RGB filters overlap, and the ISP subtracts the overlap back out with
    # negative off-diagonals. None: the camera's own RGB is written
    ccm: tuple[float, ...] | None = None

    def __post_init__(self) -> None:
        if self.tone not in TONE_CURVES:
            raise ValueError(f"tone {self.tone!r}; valid: {', '.join(TONE_CURVES)}")
        if not 0.0 < self.well_share_of_adc <= 1.0:
            raise ValueError(f"well_share_of_adc {self.well_share_of_adc}; valid: (0, 1]")
        if self.ccm is not None and (
            len(self.ccm) != 9 or not np.allclose(np.reshape(self.ccm, (3, 3)).sum(1), 1.0)
        ):
            raise ValueError(f"ccm {self.ccm}; valid: 9 numbers, a row-major 3x3 matrix whose rows sum to 1")


@dataclass
class FramePair:
    clean: np.ndarray
    attacked: np.ndarray
    intensity: float
    pattern: np.ndarray | None = None
    settings: dict = field(default_factory=dict)
    pattern_dark: np.ndarray | None = None  # the pattern's capture with the source off


# ---------------------------------------------------------------- scene, optics, sensor, ISP


def scene_reflectance(rng: np.random.Generator, height: int, width: int) -> np.ndarray:
    """Reflectance in [0.03, 0.9] per channel: a background, coloured rectangles and discs, a grating."""
    yy, xx = np.mgrid[0:height, 0:width].astype(float)
    refl = np.empty((height, width, 3))
    refl[:] = rng.uniform(0.1, 0.6, 3)
    for _ in range(rng.integers(3, 7)):
        colour = rng.uniform(0.03, 0.9, 3)
        if rng.random() < 0.5:
            y0, x0 = rng.integers(0, height - 4), rng.integers(0, width - 4)
            hh, ww = rng.integers(4, height // 2 + 4), rng.integers(4, width // 2 + 4)
            refl[y0 : y0 + hh, x0 : x0 + ww] = colour
        else:
            cy, cx, rad = rng.uniform(0, height), rng.uniform(0, width), rng.uniform(3, height / 3)
            refl[(yy - cy) ** 2 + (xx - cx) ** 2 < rad**2] = colour
    period, angle = rng.uniform(4, 12), rng.uniform(0, np.pi)
    grating = 0.5 + 0.5 * np.sin(2 * np.pi * (xx * np.cos(angle) + yy * np.sin(angle)) / period)
    region = (yy > rng.uniform(0, height / 2)) & (xx < rng.uniform(width / 3, width))
    refl[region] *= (0.6 + 0.4 * grating[region])[:, None]
    return np.clip(refl, 0.03, 0.9)


def ambient_light(rng: np.random.Generator, height: int, width: int) -> np.ndarray:
    """Illumination irradiance: a tinted light with a smooth gradient across the scene."""
    yy, xx = np.mgrid[0:height, 0:width].astype(float)
    tint = rng.uniform(0.8, 1.2, 3)
    gx, gy = rng.uniform(-0.3, 0.3, 2)
    ramp = 1 + gx * (xx / width - 0.5) + gy * (yy / height - 0.5)
    return ramp[..., None] * tint


def optics(irradiance: np.ndarray, cam: Camera) -> np.ndarray:
    """Lens PSF (core + wide scatter Gaussians) and vignetting, in linear irradiance."""
    core = ndimage.gaussian_filter(irradiance, sigma=(cam.psf_sigma_px, cam.psf_sigma_px, 0), mode="nearest")
    wide = ndimage.gaussian_filter(
        irradiance, sigma=(cam.psf_wide_sigma_px, cam.psf_wide_sigma_px, 0), mode="nearest"
    )
    out = (1 - cam.psf_wide_share) * core + cam.psf_wide_share * wide
    if cam.vignetting:
        out = out * vignette(cam.height, cam.width, cam.vignetting)[..., None]
    return out


def vignette(height: int, width: int, corner_loss: float) -> np.ndarray:
    """cos^4 falloff with the field angle, scaled so the image corner loses ``corner_loss`` of its light."""
    yy, xx = np.mgrid[0:height, 0:width].astype(float)
    r = np.hypot(yy - (height - 1) / 2, xx - (width - 1) / 2) / np.hypot(height / 2, width / 2)
    tan_corner = np.sqrt((1 - corner_loss) ** -0.5 - 1)
    return np.cos(np.arctan(r * tan_corner)) ** 4


def meter(irradiance: np.ndarray, cam: Camera) -> float:
    """Auto-exposure: the exposure at which the clipped, centre-weighted linear luminance hits the target."""
    h, w = irradiance.shape[:2]
    yy, xx = np.mgrid[0:h, 0:w].astype(float)
    weight = np.exp(-(((yy - h / 2) / (0.6 * h)) ** 2 + ((xx - w / 2) / (0.6 * w)) ** 2))
    weight /= weight.sum()
    luma = irradiance @ LUMA
    lo, hi = np.log(1e-4), np.log(1e3)
    for _ in range(40):
        mid = (lo + hi) / 2
        if (np.minimum(np.exp(mid) * luma, 1.0) * weight).sum() < cam.exposure_target:
            lo = mid
        else:
            hi = mid
    return float(np.exp((lo + hi) / 2))


def mosaic(linear: np.ndarray) -> np.ndarray:
    """RGGB Bayer sampling of an HxWx3 array into an HxW raw frame."""
    raw = linear[..., 1].copy()
    raw[0::2, 0::2] = linear[0::2, 0::2, 0]
    raw[1::2, 1::2] = linear[1::2, 1::2, 2]
    return raw


def bayer_masks(height: int, width: int) -> np.ndarray:
    masks = np.zeros((height, width, 3))
    masks[0::2, 0::2, 0] = 1
    masks[0::2, 1::2, 1] = 1
    masks[1::2, 0::2, 1] = 1
    masks[1::2, 1::2, 2] = 1
    return masks


def demosaic(raw: np.ndarray) -> np.ndarray:
    """Bilinear demosaic of an RGGB raw frame (normalised convolution, so borders stay unbiased)."""
    masks = bayer_masks(*raw.shape)
    kernel_rb = np.array([[1, 2, 1], [2, 4, 2], [1, 2, 1]], float)
    kernel_g = np.array([[0, 1, 0], [1, 4, 1], [0, 1, 0]], float)
    out = np.empty((*raw.shape, 3))
    for c, kernel in enumerate((kernel_rb, kernel_g, kernel_rb)):
        num = ndimage.convolve(raw * masks[..., c], kernel, mode="mirror")
        den = ndimage.convolve(masks[..., c], kernel, mode="mirror")
        out[..., c] = num / den
    return out


def tone_curve(linear: np.ndarray, cam: Camera) -> np.ndarray:
    x = np.clip(linear, 0.0, 1.0)
    if cam.tone == "power":
        return x ** (1 / cam.tone_gamma)
    if cam.tone == "filmic":
        # ACES fit (Narkowicz) on a 4x pre-gain, normalised to reach 1 at the sensor's saturation, then sRGB
        def aces(v):
            return v * (2.51 * v + 0.03) / (v * (2.43 * v + 0.59) + 0.14)

        x = aces(4 * x) / aces(4.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)


def sensor(
    irradiance: np.ndarray,
    exposure: float,
    cam: Camera,
    rng: np.random.Generator,
    *,
    extra_exposure: np.ndarray | None = None,
) -> np.ndarray:
    """Raw frame in [0, 1] of the ADC's range: photons (+ ``extra_exposure``, already in full-well units), shot and
    read noise, clipping at the full well, ADC (the well fills ``well_share_of_adc`` of its range)."""
    signal = exposure * irradiance
    if extra_exposure is not None:
        signal = signal + extra_exposure
    electrons = mosaic(signal) * cam.full_well_e
    electrons = rng.poisson(np.clip(electrons, 0, 50 * cam.full_well_e)).astype(float)
    electrons += rng.normal(0.0, cam.read_noise_e, electrons.shape)
    levels = 2**cam.adc_bits - 1
    code = np.clip(electrons / cam.full_well_e, 0.0, 1.0) * cam.well_share_of_adc
    return np.round(code * levels) / levels


def develop(raw: np.ndarray, cam: Camera) -> np.ndarray:
    """ISP: demosaic, colour correction (``Camera.ccm``) and tone curve, float output in [0, 1] before encoding."""
    rgb = demosaic(raw)
    if cam.ccm is not None:
        rgb = rgb @ np.reshape(cam.ccm, (3, 3)).T
    return tone_curve(rgb, cam)


def random_ccm(rng: np.random.Generator) -> tuple[float, ...]:
    """A colour correction matrix like those of consumer cameras: each off-diagonal -0.45 to 0, the diagonal
    what makes its row sum to 1 (1.0-1.9)."""
    off = rng.uniform(-0.45, 0.0, (3, 3))
    np.fill_diagonal(off, 0.0)
    matrix = off + np.diag(1.0 - off.sum(1))
    return tuple(float(v) for v in matrix.ravel())


def encode(image01: np.ndarray, cam: Camera) -> np.ndarray:
    """8-bit quantisation and a JPEG round trip (4:4:4 so tiny test frames keep their colour)."""
    img = Image.fromarray(np.round(np.clip(image01, 0, 1) * 255).astype(np.uint8))
    buffer = io.BytesIO()
    img.save(buffer, format="JPEG", quality=cam.jpeg_quality, subsampling=0)
    return np.asarray(Image.open(io.BytesIO(buffer.getvalue())).convert("RGB")).copy()


def capture(
    irradiance: np.ndarray,
    cam: Camera,
    rng: np.random.Generator,
    *,
    exposure: float | None = None,
    extra_exposure: np.ndarray | None = None,
    raw_hook=None,
) -> tuple[np.ndarray, float]:
    """Scene irradiance (HxWx3, linear) -> developed float frame and the exposure used."""
    at_sensor = optics(irradiance, cam)
    if exposure is None:
        exposure = meter(at_sensor if extra_exposure is None else at_sensor + extra_exposure, cam)
    raw = sensor(at_sensor, exposure, cam, rng, extra_exposure=extra_exposure)
    if raw_hook is not None:
        raw = raw_hook(raw)
    return develop(raw, cam), exposure


def scene(rng: np.random.Generator, cam: Camera) -> tuple[np.ndarray, np.ndarray]:
    """(reflectance, ambient irradiance) of a fresh procedural scene."""
    return scene_reflectance(rng, cam.height, cam.width), ambient_light(rng, cam.height, cam.width)


class Session:
    """One capture session's exposure: a camera with auto-exposure meters every scene; one without keeps the
    exposure metered on the session's first scene (a manual setting). Re-metering every scene on a manual camera
    scales each clean frame by a factor nothing in the pair records: against a laser pattern recorded once, or
    against the surface's reflectance, which sets how much projected light it returns (until session 15 the
    projection renderer did this; its sensor-gamma case was then missed on 4 of 8 master seeds, on 0 of 8 since:
    docs/bench/camsim_session15.md)."""

    def __init__(self, cam: Camera) -> None:
        self.cam = cam
        self.first_exposure: float | None = None

    def clean(self, irradiance: np.ndarray, rng: np.random.Generator) -> tuple[np.ndarray, float]:
        """The clean frame of a scene and the exposure it was taken at."""
        if self.first_exposure is None or self.cam.auto_exposure:
            metered = meter(optics(irradiance, self.cam), self.cam)
            if self.first_exposure is None:
                self.first_exposure = metered
            return capture(irradiance, self.cam, rng, exposure=metered)
        return capture(irradiance, self.cam, rng, exposure=self.first_exposure)


def intensities(rng: np.random.Generator, n: int, low: float = 0.2, high: float = 1.0) -> np.ndarray:
    """Stratified attack intensities so every run spans the range."""
    edges = np.linspace(low, high, n + 1)
    return rng.permutation(rng.uniform(edges[:-1], edges[1:]))


# ---------------------------------------------------------------- laser blinding


def laser_spot(
    cam: Camera, centre: tuple[float, float], colour: np.ndarray, *, core_px: float, halo: tuple | None
) -> np.ndarray:
    """Laser irradiance per unit power at the sensor: a Gaussian core with a wider bloom (defocused beam) and,
    when ``halo=(amplitude, scale_px, exponent)``, a glare tail amplitude * (1 + (r/scale)^2)^(-exponent/2)."""
    yy, xx = np.mgrid[0 : cam.height, 0 : cam.width].astype(float)
    r2 = (yy - centre[0]) ** 2 + (xx - centre[1]) ** 2
    profile = np.exp(-r2 / (2 * core_px**2)) + 0.15 * np.exp(-r2 / (2 * (2.5 * core_px) ** 2))
    if halo is not None:
        amplitude, scale_px, exponent = halo
        profile = profile + amplitude * (1 + r2 / scale_px**2) ** (-exponent / 2)
    return profile[..., None] * colour


def speckle(rng: np.random.Generator, height: int, width: int, *, grain_px: float, looks: int) -> np.ndarray:
    """A laser speckle intensity field of mean 1 (HxW): coherent light scattered by a rough surface interferes
    into grains whose size is set by the aperture (a complex Gaussian field low-passed to ``grain_px``, its squared
    magnitude exponential with contrast 1); ``looks`` independent patterns (polarisation, laser modes, motion
    within the exposure) add, lowering the contrast to 1/sqrt(looks). Any micro-motion of laser, surface or camera
    draws a new pattern, so a frame's speckle is not the one of a pattern recorded at another time."""
    total = np.zeros((height, width))
    for _ in range(looks):
        field = rng.normal(size=(height, width)) + 1j * rng.normal(size=(height, width))
        field = ndimage.gaussian_filter(field.real, grain_px) + 1j * ndimage.gaussian_filter(
            field.imag, grain_px
        )
        intensity = np.abs(field) ** 2
        total += intensity / intensity.mean()
    return total / looks


LASER_COLOURS = {
    "red": np.array([1.0, 0.10, 0.04]),
    "green": np.array([0.12, 1.0, 0.22]),
    "blue": np.array([0.05, 0.25, 1.0]),
}


def laser_blinding_pairs(
    rng: np.random.Generator,
    cam: Camera,
    n_pairs: int,
    *,
    halo: bool = False,
    digital_alpha: float | None = None,
    speckle_looks: int | None = None,
    dark_frame: bool = False,
) -> list[FramePair]:
    """Laser blinding frame pairs and the laser pattern recorded without a scene.

    Physical (``digital_alpha=None``): attacked irradiance = scene + power * spot; the sensor saturates and, when the
    camera has auto-exposure, the metered exposure drops as the laser gets brighter (and every clean scene is metered
    for itself, so the laser's light stands in another ratio to each clean frame). The pattern is one capture of
    the laser alone (dark room, the first clean scene's exposure, kept for the session unless the camera has
    auto-exposure) at a reference power: the peak power of the pairs without a glare tail; with one, the power at
    which the capture's core fills 50-90% of the full well, as a beam-profile measurement is exposed (a
    saturated core hides the profile). The tail, 0.2-0.8% of the core's peak a quarter of the frame's diagonal out
    and falling as a power (1.5-2.2) of the distance beyond 3-6 px, then sinks into the capture's dark noise and
    8-bit steps, while at the attack's tens of times that power it lights the scene far around the spot (on
    average 1-14 grey levels over the frame at intensity 0.6 over 20 draws, docs/bench/camsim_glare_size.py): glare the pattern does not
    hold. (A capture at a few percent of the attack's power still saturates its core and keeps the tail where the
    attack shows it.)
    ``digital_alpha``: the paper's blend (1 - a) clean + a pattern with a = digital_alpha * intensity, in 8-bit
    output space (the null case). ``speckle_looks`` (with ``digital_alpha``): the blended laser light carries a fresh
    speckle pattern per frame (``speckle``, grains of 1-2 px), which the recorded pattern does not hold: an effect
    the library has no name for. ``dark_frame``: the pattern's capture is repeated with the laser off (the same dark
    room and exposure, fresh noise), as beam profilers record one, from a stream of its own so that every other
    draw is the one without it."""
    colour = LASER_COLOURS[rng.choice(list(LASER_COLOURS))]
    # drawn only with speckle, so every other case keeps its draws
    grain_px = rng.uniform(1.0, 2.0) if speckle_looks else None
    centre = (rng.uniform(0.3, 0.7) * cam.height, rng.uniform(0.3, 0.7) * cam.width)
    halo_params = None
    if halo:
        # the glare is drawn by where it shows: its level a quarter of the frame's diagonal from the spot, as a
        # share of the core's peak. Drawn as an amplitude of 0.5-1.5% of the core at 1-2.5 px scales (until
        # session 12), the tail changed the blinded frames by at most 0.43 grey levels on average (measured over 13
        # draws), under the spot's own bloom and the frames' noise: a planted effect no calibration could see
        scale_px, exponent = rng.uniform(3.0, 6.0), rng.uniform(1.5, 2.2)
        at_quarter = np.exp(rng.uniform(np.log(2e-3), np.log(8e-3)))
        quarter = 0.25 * np.hypot(cam.height, cam.width)
        halo_params = (at_quarter * (1 + (quarter / scale_px) ** 2) ** (exponent / 2), scale_px, exponent)
    spot = laser_spot(cam, centre, colour, core_px=rng.uniform(2.5, 4.0), halo=halo_params)
    peak_power = rng.uniform(40, 120)  # full wells per unit exposure at the core, at intensity 1
    core_fill = rng.uniform(0.5, 0.9) if halo else None
    pairs = []
    dark = 0.01 * ambient_light(rng, cam.height, cam.width)
    session = Session(cam)
    pattern_u8 = dark_u8 = None
    for intensity in intensities(rng, n_pairs):
        refl, light = scene(rng, cam)
        clean, exposure = session.clean(refl * light, rng)
        if pattern_u8 is None:
            # recorded at the session's first exposure, kept for the session
            pattern_exposure = session.first_exposure
            at_core = float(optics(spot, cam).max()) * pattern_exposure
            reference = peak_power if core_fill is None else core_fill / at_core
            if dark_frame:
                dark_rng = np.random.default_rng(rng.bit_generator.state["state"]["state"])
                dark_u8 = encode(capture(dark, cam, dark_rng, exposure=pattern_exposure)[0], cam)
            pattern, _ = capture(dark + reference * spot, cam, rng, exposure=pattern_exposure)
            pattern_u8 = encode(pattern, cam)
        if digital_alpha is not None:
            attacked, _ = capture(refl * light, cam, rng, exposure=exposure)
            a = digital_alpha * intensity
            laser = pattern_u8 / 255.0
            if speckle_looks:
                # a saturated pattern pixel records light at or far above the clip, which speckle leaves above it
                grains = speckle(rng, cam.height, cam.width, grain_px=grain_px, looks=speckle_looks)
                laser = np.where(pattern_u8 == 255, 1.0, laser * grains[..., None])
            attacked_u8 = encode((1 - a) * quantised(attacked) + a * np.clip(laser, 0.0, 1.0), cam)
        else:
            irradiance = refl * light + intensity * peak_power * spot
            attacked, _ = capture(irradiance, cam, rng, exposure=None if cam.auto_exposure else exposure)
            attacked_u8 = encode(attacked, cam)
        pairs.append(
            FramePair(encode(clean, cam), attacked_u8, float(intensity), pattern_u8, pattern_dark=dark_u8)
        )
    return pairs


def quantised(image01: np.ndarray) -> np.ndarray:
    return np.round(np.clip(image01, 0, 1) * 255) / 255


# ---------------------------------------------------------------- light projection


def projected_image(rng: np.random.Generator, height: int, width: int) -> np.ndarray:
    """A projector frame (digital values in [0, 1]): a few saturated-colour shapes on black."""
    yy, xx = np.mgrid[0:height, 0:width].astype(float)
    img = np.zeros((height, width, 3))
    for _ in range(rng.integers(2, 5)):
        colour = rng.choice([0.0, 0.5, 1.0], 3)
        if colour.max() == 0:
            colour[rng.integers(3)] = 1.0
        cy, cx = rng.uniform(0.2, 0.8) * height, rng.uniform(0.2, 0.8) * width
        ry, rx = rng.uniform(0.15, 0.35) * height, rng.uniform(0.15, 0.35) * width
        img[((yy - cy) / ry) ** 2 + ((xx - cx) / rx) ** 2 < 1] = colour
    return img


def rebalanced(frame: np.ndarray, reference: np.ndarray, strength: float) -> np.ndarray:
    """``frame`` (HxWx3 in [0, 1]) after a grey-world white balance settled on ``reference`` re-adapts to it: each
    channel scaled by (its grey-world gain on ``frame`` / on ``reference``) ** ``strength``."""
    if not strength:
        return frame

    def gains(image: np.ndarray) -> np.ndarray:
        means = image.reshape(-1, 3).mean(0)
        return means.mean() / means

    return np.clip(frame * (gains(frame) / gains(reference)) ** strength, 0.0, 1.0)


def light_projection_pairs(
    rng: np.random.Generator,
    cam: Camera,
    n_pairs: int,
    *,
    crosstalk: float = 0.0,
    power: float = 0.8,
    digital_alpha: float | None = None,
    falloff: float = 0.0,
    pattern_record: str = "board",
    reflectance_modulated: bool = True,
    white_balance: float = 0.0,
) -> list[FramePair]:
    """Light projection pairs; the pattern is the projector's frame captured on a white board in the dark
    (``pattern_record="board"``) or the frame the projector was sent (``"emitted"``, what SLAP's tables record as
    the projected colour). A board capture is taken through the camera's own colour filters, so the camera's
    response to the projector primaries (the cross-talk ``M``) and the projector gamma are already in it and
    cannot show in the pairs; only the emitted frame leaves them to be found.

    Physical: surface irradiance = ambient + power * intensity * M (projector_frame ** 2.2), where M is the camera's
    3x3 response to the projector's primaries (diagonal 1, off-diagonal ``crosstalk`` on average); the camera sees
    reflectance * irradiance, so bright projector light on a bright surface saturates. ``digital_alpha``: the paper's
    overlay with transparency t = digital_alpha * intensity in output space (null). ``falloff``: the projected light
    loses this share at the frame corner (projector lens vignetting), which the recorded pattern does not show (the
    board was captured with a different lens-to-board geometry): an effect the library has no name for.
    ``white_balance``: the ISP's grey-world white balance, settled on the clean scene, re-adapts to the projected
    light's colour cast: the attacked frame's channels are scaled by the change of grey-world gains from the clean
    frame to it, to this power (1: full adaptation): an effect the library has no name for.
    ``reflectance_modulated=False`` is a counterfactual for measuring what the reflectance term changes (benches
    only): every surface returns the projector's light as the scene's mean reflectance would."""
    mix = np.eye(3) + crosstalk * rng.uniform(0.5, 1.5, (3, 3)) * (1 - np.eye(3))
    board = 0.85
    session = Session(cam)
    pairs = []
    for intensity in intensities(rng, n_pairs):
        refl, light = scene(rng, cam)
        clean, exposure = session.clean(refl * light, rng)
        frame = projected_image(rng, cam.height, cam.width)
        projector = (frame**2.2) @ mix.T
        pattern, _ = capture(board * power * projector, cam, rng, exposure=exposure)
        pattern_u8 = encode(pattern, cam)
        if pattern_record == "emitted":
            pattern_u8 = np.round(frame * 255).astype(np.uint8)
        if digital_alpha is not None:
            attacked, _ = capture(refl * light, cam, rng, exposure=exposure)
            t = digital_alpha * intensity
            if falloff:
                t = t * vignette(cam.height, cam.width, falloff)[..., None]
            blend = (1 - t) * quantised(attacked) + t * pattern_u8 / 255.0
            attacked_u8 = encode(rebalanced(blend, clean, white_balance), cam)
        else:
            returned = refl if reflectance_modulated else refl.mean()
            irradiance = refl * light + returned * intensity * power * projector
            attacked, _ = capture(irradiance, cam, rng, exposure=exposure)
            attacked_u8 = encode(rebalanced(attacked, clean, white_balance), cam)
        record = "emitted" if pattern_record == "emitted" else "captured"
        pairs.append(
            FramePair(
                encode(clean, cam), attacked_u8, float(intensity), pattern_u8, {"pattern_record": record}
            )
        )
    return pairs


# ---------------------------------------------------------------- laser colour strip (rolling shutter)


def pulse_overlap(
    rows: int, exposure_rows: float, period_rows: float, on_rows: float, phase_rows: float
) -> np.ndarray:
    """Per row, the time (in row times) its exposure window [i, i + exposure) overlaps the laser's on-intervals
    [phase + k period, phase + k period + on)."""
    starts = np.arange(rows, dtype=float)
    ends = starts + exposure_rows
    k = np.arange(
        np.floor((-on_rows - phase_rows) / period_rows) - 1, np.ceil((rows + exposure_rows) / period_rows) + 2
    )
    on_start = phase_rows + k * period_rows
    lo = np.maximum(starts[:, None], on_start[None, :])
    hi = np.minimum(ends[:, None], on_start[None, :] + on_rows)
    return np.clip(hi - lo, 0, None).sum(axis=1)


def laser_strip_pairs(
    rng: np.random.Generator,
    cam: Camera,
    n_pairs: int,
    *,
    multi_stripe: bool = False,
    paper_band: float | None = None,
    band_profile: np.ndarray | None = None,
    speckle_looks: int | None = None,
) -> list[FramePair]:
    """Rolling-shutter laser stripes. Row i integrates laser light for the overlap of its exposure with the pulse
    train (energy = power * overlap, added to the scene's exposure in linear electrons, then clipped at the well).
    One pulse per frame (period longer than the readout) or, with ``multi_stripe``, a period of a third to a half
    of the frame so 2-3 stripes show. The phase is random per frame (laser and camera are not synchronised).
    ``paper_band``: the paper's Gaussian-weighted band over rows h/3 .. 2h/3, strength paper_band * intensity,
    added in output space (null); ``band_profile`` (HxW, peak 1) replaces the paper's Gaussian when the null must
    use another implementation's unstated constants (the paper gives no sigmas or centre). ``speckle_looks`` (with
    ``paper_band``): the band's laser light carries a fresh speckle pattern per frame (``speckle``, grains of 1-2
    px): an effect the library has no name for."""
    h = cam.height
    # drawn only with speckle, so every other case keeps its draws
    grain_px = rng.uniform(1.0, 2.0) if speckle_looks else None
    profile = paper_band_profile(cam) if band_profile is None else band_profile[..., None]
    colour = LASER_COLOURS[rng.choice(list(LASER_COLOURS))] * rng.uniform(0.8, 1.0)
    exposure_rows = rng.uniform(2, 8)
    if multi_stripe:
        period_rows = rng.uniform(h / 3, h / 2)
        on_rows = rng.uniform(0.15, 0.3) * period_rows
    else:
        period_rows = 10.0 * h
        on_rows = rng.uniform(0.08, 0.2) * h
    power = rng.uniform(0.06, 0.12)  # full wells per row time of overlap, at intensity 1
    session = Session(cam)
    pairs = []
    for intensity in intensities(rng, n_pairs):
        refl, light = scene(rng, cam)
        clean, exposure = session.clean(refl * light, rng)
        if paper_band is not None:
            attacked, _ = capture(refl * light, cam, rng, exposure=exposure)
            band = paper_band * intensity * profile * colour
            if speckle_looks:
                band = band * speckle(rng, h, cam.width, grain_px=grain_px, looks=speckle_looks)[..., None]
            attacked_u8 = encode(quantised(attacked) + band, cam)
        else:
            phase = rng.uniform(0, period_rows) if multi_stripe else rng.uniform(-0.2 * h, 0.9 * h)
            lit = pulse_overlap(h, exposure_rows, period_rows, on_rows, phase) * intensity * power
            extra = np.broadcast_to(lit[:, None, None] * colour, (h, cam.width, 3))
            attacked, _ = capture(refl * light, cam, rng, exposure=exposure, extra_exposure=extra)
            attacked_u8 = encode(attacked, cam)
        pairs.append(FramePair(encode(clean, cam), attacked_u8, float(intensity)))
    return pairs


def paper_band_profile(cam: Camera) -> np.ndarray:
    """The paper's laser strip intensity function (Appendix A) on rows h/3 .. 2h/3: an uncorrelated 2D Gaussian
    centred on the band, sigma = band height / 2 across rows and width / 2 across columns."""
    h, w = cam.height, cam.width
    yy, xx = np.mgrid[0:h, 0:w].astype(float)
    start, end = h // 3, 2 * (h // 3)
    centre_p, centre_q = (start + end) / 2, w / 2
    sigma_p, sigma_q = (end - start) / 2, w / 2
    g = np.exp(-0.5 * (((yy - centre_p) / sigma_p) ** 2 + ((xx - centre_q) / sigma_q) ** 2))
    g[(yy < start) | (yy >= end)] = 0
    return g[..., None]


# ---------------------------------------------------------------- EM colour strip


def band_rows(height: int, period: float, phase: float) -> np.ndarray:
    """Boolean per row: inside a corrupted band (first half of each period, shifted by ``phase``)."""
    return ((np.arange(height) - phase) % period) < period / 2


def paper_colour_map(image01: np.ndarray) -> np.ndarray:
    """The paper's EM colour strip decoding (Appendix A): R' = 2.5 G, G' = (R + B) / 2 - 50, B' = 2.5 G."""
    r, g, b = image01[..., 0], image01[..., 1], image01[..., 2]
    out = np.stack([2.5 * g, (r + b) / 2 - 50 / 255, 2.5 * g], axis=-1)
    return np.clip(out, 0, 1)


def em_strip_pairs(
    rng: np.random.Generator,
    cam: Camera,
    n_pairs: int,
    *,
    paper_map: bool = False,
    lost_lines: str = "banded",
    pixel_slip: int = 0,
) -> list[FramePair]:
    """EM colour strip: rows demosaiced with the wrong Bayer phase because lines were lost on the bus.

    ``lost_lines="banded"``: bands of rows with a period fixed per case and a random phase per frame; a lost line
    at each band start shifts the raw rows by one, so the band is demosaiced with the wrong Bayer phase, and a
    second lost line at the band end restores it. ``"single"``: the interference hits once per frame, at a
    uniformly random row; one lost line shifts every later raw row by one, so the wrong phase runs to the frame's
    end (nothing restores it before the next frame's sync). ``paper_map``: the paper's fixed colour map on the
    bands in output space (null). ``pixel_slip`` (with ``paper_map``): the interference also drops pixel clocks on
    the parallel bus, so each corrupted row arrives up to this many pixels early (a slip drawn per row, the row's
    end filled from its last pixel): an effect the library has no name for."""
    if lost_lines not in ("banded", "single"):
        raise ValueError(f"lost_lines {lost_lines!r}; valid: banded, single")
    h = cam.height
    period = float(rng.integers(h // 5, h // 2)) // 2 * 2
    session = Session(cam)
    pairs = []
    for intensity in intensities(rng, n_pairs):
        refl, light = scene(rng, cam)
        clean, exposure = session.clean(refl * light, rng)
        if lost_lines == "single":
            band = np.arange(h) >= rng.integers(0, h)
        else:
            band = band_rows(h, period, rng.uniform(0, period))
        if paper_map:
            attacked, _ = capture(refl * light, cam, rng, exposure=exposure)
            attacked = quantised(attacked)
            attacked[band] = paper_colour_map(attacked[band])
            if pixel_slip:
                for row in np.flatnonzero(band):
                    slip = int(rng.integers(0, pixel_slip + 1))
                    if slip:
                        attacked[row, :-slip] = attacked[row, slip:].copy()
                        attacked[row, -slip:] = attacked[row, -slip - 1]
        else:

            def flip(raw, band=band):
                shifted = raw.copy()
                rows = np.flatnonzero(band)
                shifted[rows] = raw[np.minimum(rows + 1, h - 1)]
                return shifted

            attacked, _ = capture(refl * light, cam, rng, exposure=exposure, raw_hook=flip)
        pairs.append(FramePair(encode(clean, cam), encode(attacked, cam), float(intensity)))
    return pairs


# ---------------------------------------------------------------- EM truncation


def em_truncation_pairs(
    rng: np.random.Generator,
    cam: Camera,
    n_pairs: int,
    *,
    free_position: bool = False,
    hum_bars: float = 0.0,
    count_spread: float = 0.0,
) -> list[FramePair]:
    """EM truncation: rows [s, s + n) are lost, the frame moves up and its last n rows are stitched below (the
    paper's Appendix A), with n = int(h * r), r = ratio_per_intensity * intensity. The paper puts s = n; with
    ``free_position`` the corrupted address is anywhere, s uniform in [0, h - n]. ``hum_bars``: EMI also couples
    into the analogue gain as a slow row-periodic ripple of this relative depth (no library effect names it).
    ``count_spread``: the interference's timing varies from frame to frame, so the count is the nearest whole row
    to h r (1 + g), g normal with this relative standard deviation (the library's count law is a floor with a
    bounded, uniform jitter: a different form)."""
    h = cam.height
    ratio_per_intensity = rng.uniform(0.2, 0.3)
    ripple_period, ripple_phase = rng.uniform(0.3, 0.6) * h, rng.uniform(0, 2 * np.pi)
    session = Session(cam)
    pairs = []
    for intensity in intensities(rng, n_pairs, 0.3, 1.0):
        refl, light = scene(rng, cam)
        clean, exposure = session.clean(refl * light, rng)
        attacked, _ = capture(refl * light, cam, rng, exposure=exposure)
        n = int(h * ratio_per_intensity * intensity)
        if count_spread:
            n = int(
                np.clip(
                    np.rint(h * ratio_per_intensity * intensity * (1 + rng.normal(0, count_spread))),
                    0,
                    h // 2,
                )
            )
        start = int(rng.integers(0, h - n + 1)) if free_position else n
        rows = np.concatenate([np.arange(0, start), np.arange(start + n, h), np.arange(h - n, h)])
        attacked = quantised(attacked)[rows]
        if hum_bars:
            gain = 1 + hum_bars * np.sin(2 * np.pi * np.arange(h) / ripple_period + ripple_phase)
            attacked = attacked * gain[:, None, None]
        pairs.append(FramePair(encode(clean, cam), encode(attacked, cam), float(intensity)))
    return pairs


# ---------------------------------------------------------------- ultrasound blur


def path_blur(irradiance: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """Average of the image displaced by each (dy, dx) in ``offsets`` (bilinear sampling, edges repeated)."""
    h, w = irradiance.shape[:2]
    yy, xx = np.mgrid[0:h, 0:w].astype(float)
    acc = np.zeros_like(irradiance)
    for dy, dx in offsets:
        for c in range(irradiance.shape[2]):
            acc[..., c] += ndimage.map_coordinates(
                irradiance[..., c], [yy - dy, xx - dx], order=1, mode="nearest"
            )
    return acc / len(offsets)


def uniform_path(length: float, samples: int = 24) -> np.ndarray:
    """Positions along a path travelled at constant speed from 0 to ``length`` during the exposure: the centres of
    ``samples`` equal steps, so their spread is the continuous path's (``length / sqrt(12)``, to 1 / samples^2).
    Samples at both ends (``np.linspace(0, length, 24)``, until session 47) spread 4.3% wider, and the library's
    paper blur left the null's frames displaced by 0.03-0.10 px (docs/bench/session47.md)."""
    return (np.arange(samples) + 0.5) / samples * length


def triangle_wave_path(length: float, cycles: float, phase: float, samples: int = 64) -> np.ndarray:
    """Positions, centred on the rest position, of a path swept back and forth at constant speed over ``length``
    (a triangle wave of ``cycles`` per exposure starting ``phase`` of a cycle in), at ``samples`` equal time steps:
    every position is visited equally often, where a resonance's sinusoid dwells at both ends."""
    t = (np.arange(samples) + 0.5) / samples
    return length * (2 * np.abs((cycles * t + phase) % 1.0 - 0.5) - 0.5)


def disc_offsets(diameter: float, samples: int = 144) -> np.ndarray:
    """(dy, dx) positions filling a disc of ``diameter`` px uniformly (a sunflower lattice): a defocus PSF."""
    radius = np.sqrt((np.arange(samples) + 0.5) / samples) * diameter / 2
    angle = np.arange(samples) * np.pi * (3 - np.sqrt(5))
    return np.stack([radius * np.sin(angle), radius * np.cos(angle)], axis=1)


def rotation_blur(image: np.ndarray, max_angle_rad: float, samples: int = 24) -> np.ndarray:
    h, w = image.shape[:2]
    yy, xx = np.mgrid[0:h, 0:w].astype(float)
    cy, cx = (h - 1) / 2, (w - 1) / 2
    acc = np.zeros_like(image)
    for angle in np.linspace(0, max_angle_rad, samples):
        ys = cy + (yy - cy) * np.cos(angle) - (xx - cx) * np.sin(angle)
        xs = cx + (yy - cy) * np.sin(angle) + (xx - cx) * np.cos(angle)
        for c in range(image.shape[2]):
            acc[..., c] += ndimage.map_coordinates(image[..., c], [ys, xs], order=1, mode="nearest")
    return acc / samples


def ultrasound_blur_pairs(
    rng: np.random.Generator,
    cam: Camera,
    n_pairs: int,
    *,
    path: str = "linear",
    amplitude_px: float | None = None,
) -> list[FramePair]:
    """Ultrasound blur: the stabiliser moves the image during the exposure.

    ``path``: "linear" (the paper's linear component: uniform samples from 0 to d, d = intensity * D, in output
    space: the null), "sweep" (the same one-way constant-speed path, integrated in linear irradiance before the
    sensor, as a real exposure integrates any motion), "sinusoidal" (resonance: x(t) = (d / 2) sin(2 pi f t + phi) with 5-9 non-integer cycles per
    exposure and a random phase, integrated in linear irradiance before the sensor, so the dwell time is
    arcsine-weighted toward both ends of the path), "rotation" (the paper's rotational component, 0 .. theta,
    theta = intensity * Theta, in output space: an effect the library has no name for), "defocus" (the lens out of
    focus instead of any motion: a uniform disc of diameter d in linear irradiance, ``disc_offsets``: an effect the
    library has no name for), "triangle" (the resonance's centred path swept at constant speed, a triangle wave of
    as many cycles, in linear irradiance: the dwell time is uniform, not arcsine: an effect the library has no name
    for)."""
    direction = rng.uniform(0, np.pi)
    amplitude = amplitude_px if amplitude_px is not None else rng.uniform(8, 14)
    unit = np.array([np.sin(direction), np.cos(direction)])
    cycles = rng.uniform(5.2, 8.8)
    session = Session(cam)
    pairs = []
    for intensity in intensities(rng, n_pairs, 0.3, 1.0):
        refl, light = scene(rng, cam)
        # a blur is only seen on edges: a checkerboard texture over the whole scene (blocks of 4-7 px)
        block = rng.uniform(4, 7)
        yy, xx = np.mgrid[0 : cam.height, 0 : cam.width]
        refl = refl * np.where((yy // block + xx // block) % 2 == 0, 1.0, 0.4)[..., None]
        clean, exposure = session.clean(refl * light, rng)
        d = intensity * amplitude
        if path == "sinusoidal":
            t = (np.arange(64) + 0.5) / 64
            shifts = (d / 2) * np.sin(2 * np.pi * cycles * t + rng.uniform(0, 2 * np.pi))
            attacked, _ = capture(
                path_blur(refl * light, shifts[:, None] * unit), cam, rng, exposure=exposure
            )
            attacked = quantised(attacked)
        elif path == "sweep":
            attacked, _ = capture(
                path_blur(refl * light, uniform_path(d)[:, None] * unit), cam, rng, exposure=exposure
            )
            attacked = quantised(attacked)
        elif path == "triangle":
            shifts = triangle_wave_path(d, cycles, rng.uniform(0, 1))
            attacked, _ = capture(
                path_blur(refl * light, shifts[:, None] * unit), cam, rng, exposure=exposure
            )
            attacked = quantised(attacked)
        elif path == "defocus":
            attacked, _ = capture(path_blur(refl * light, disc_offsets(d)), cam, rng, exposure=exposure)
            attacked = quantised(attacked)
        else:
            attacked, _ = capture(refl * light, cam, rng, exposure=exposure)
            attacked = quantised(attacked)
            if path == "linear":
                attacked = path_blur(attacked, uniform_path(d)[:, None] * unit)
            elif path == "rotation":
                attacked = rotation_blur(attacked, np.deg2rad(intensity * amplitude))
            else:
                raise ValueError(
                    f"path {path!r}; valid: defocus, linear, rotation, sinusoidal, sweep, triangle"
                )
        pairs.append(FramePair(encode(clean, cam), encode(attacked, cam), float(intensity)))
    return pairs


# ---------------------------------------------------------------- writer


def write_pairs(folder, pairs: list[FramePair]) -> None:
    """The calibration CLI's frame-pair input: PNGs and pairs.csv (clean, attacked[, pattern[, pattern_dark]],
    intensity and the pairs' settings, e.g. pattern_record)."""
    from pathlib import Path

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    with_pattern = pairs[0].pattern is not None
    with_dark = pairs[0].pattern_dark is not None
    settings = list(pairs[0].settings)
    header = (
        ["clean", "attacked"]
        + (["pattern"] if with_pattern else [])
        + (["pattern_dark"] if with_dark else [])
        + ["intensity", *settings]
    )
    lines = [",".join(header)]
    for i, pair in enumerate(pairs):
        names = [f"clean_{i:03d}.png", f"attacked_{i:03d}.png"]
        Image.fromarray(pair.clean).save(folder / names[0])
        Image.fromarray(pair.attacked).save(folder / names[1])
        if with_pattern:
            names.append(f"pattern_{i:03d}.png")
            Image.fromarray(pair.pattern).save(folder / names[2])
        if with_dark:
            names.append(f"pattern_dark_{i:03d}.png")
            Image.fromarray(pair.pattern_dark).save(folder / names[-1])
        lines.append(",".join([*names, f"{pair.intensity:.6f}", *(str(pair.settings[k]) for k in settings)]))
    (folder / "pairs.csv").write_text("\n".join(lines) + "\n")


__all__ = [
    "Camera",
    "FramePair",
    "em_strip_pairs",
    "em_truncation_pairs",
    "laser_blinding_pairs",
    "laser_strip_pairs",
    "light_projection_pairs",
    "replace",
    "ultrasound_blur_pairs",
    "write_pairs",
]
