"""Laser blinding frame pairs: the scene, a capture of the laser alone, and the blinded frame.

Base: the paper's alpha blend of the scene and the encoded pattern. ``linear_light_saturation`` reads the pattern
as laser irradiance instead, which needs three corrections any capture of a laser "alone" calls for:

* the capture's dark level (the dark room's residual light and the sensor's black level) is not laser light and
  does not grow with the laser's power: the per-channel median of the tenth of the capture's pixels farthest from
  the spot is subtracted in linear light. One level misreads a dark room whose light varies over the frame: the
  capture is scaled to the attack's power by a gain of tens to a hundred, and the room's gradient, read as laser
  light, lit the frames by up to 0.12 full wells per unit intensity and stood in for glare (on the independent
  simulator's halo case the glare's fit ran to its bound, docs/bench/session79.md). With a dark frame
  (``pattern_dark``: the capture repeated with the laser off, as beam profilers record one), the level varies over
  the frame as the dark frame's light does (``capture.dark_field``); without one, as the room's linear gradient
  does, read from the capture's part that is odd under the reflection about the spot, where the beam and its glare
  are even (``capture.room_gradient``; on the simulator's halo case the glare was then named on the three draws
  that had missed it, docs/bench/session96.md);
* where the capture itself saturated, the laser's irradiance is unknown (at least the full well): it is
  extrapolated into the saturated core as a Gaussian beam of width ``core_sigma``: a channel saturated out to
  radius ``R`` (from its saturated area) rises at depth ``d = R - r`` inside it by ``exp((2 R d - d^2) / (2
  sigma^2))``, the Gaussian's ``exp((R^2 - r^2) / (2 sigma^2))`` written with the distance ``d`` (reference pixels)
  to the nearest unsaturated pixel, so that saturated areas of any shape are followed. This matters whenever the
  blinded frame is exposed less than the capture (auto-exposure, a weaker beam): the saturated disc then
  shrinks, and a model holding the core at the full well would paint it grey instead;
* the capture's noise is not laser light either, and the beam goes on below the capture's noise floor: the
  capture is read as a smoothed beam profile, continued below its floor with the fall-off of its edge, and its
  fainter channels are read as the laser's channel times the laser's colour (``capture.beam_profile``). A capture
  exposed for the beam's profile is tens of times weaker than the attack, and that ratio would otherwise multiply
  its noise into the frames and drop the beam's faint outskirts, which the ``halo_power_law`` then stood in for
  with its exponent at the bound (measured on the independent simulator).

``halo_power_law`` is glare, so it adds light and builds on ``linear_light_saturation``; it is fitted by its level
at ``GLARE_REFERENCE_PX`` from the spot (where the frames show it) and its exponent; its inner scale lies inside
the clipped core (``GLARE_INNER_SCALE_REF_PX``). The capture holds the glare too, at its own power: where it
measured the laser's light, its beam already carries the glare (scaled with it by the gain) less the share its dark
level took out (the glare at ``capture.dark_level_radius``), so the halo adds back only that share there; below its
noise floor the glare is the larger of the halo and the beam's continued edge. Added everywhere (until session 24),
it counted the measured glare twice and missed the dark level's share, and fits answered with a glare whose exponent
ran to its bound (independent simulator's halo case, docs/bench/camsim_session24.md). ``tone_shoulder``
(also on linear light) composes in the log-logistic tone curve of ``calibration/tone.py`` instead of sRGB: a filmic
camera stores the laser's light on a curve no power law follows (on the independent simulator, a power law fitted
to one ran to its bound and a halo took over the laser's whole spot). It is an alternative to ``sensor_gamma``, not
a refinement of it: the shoulder alone follows a filmic curve to half a grey level, and under a power law of its own
the curve can stretch the light's scale freely, so the laser's gain is no longer pinned by the frames.

``auto_exposure`` is a meter, not a divisor: the camera scales its exposure by ``k`` so that the blinded frame's
*clipped* mean level (what a meter reads from the sensor) equals the clean frame's, ``mean(min(k (scene + light),
1)) = mean(min(scene, 1))``, solved per frame on a fixed pixel sample; the fitted ``auto_exposure`` ``a`` applies
``k ** a`` (0: no reaction; 1: the uniform meter; above 1: a meter weighting the spot's region more than the frame
average, as centre-weighted meters do when the spot is central). An auto-exposure commonly meters its raw channels'
luminance (Rec. 709 weights, ``physics.meter_light``; camsim's does), light the model holds only under
``colour_correction``: there the meter reads luminance (``meter_reads``), elsewhere the channel mean of the output a
matrix mixed, which neither form follows (docs/bench/session91.md, section 4). With the channel mean a
colour-correcting camera's matrix took a channel's light at its bound in the meter's place
(docs/bench/session95.md); a luminance meter on every camera, tried in sessions 71 and 91 before the saturated core
was continued with its narrower beam, lost the frames' exposures on colour-correcting cameras (planted causes named
on 1 of 8 draws against 5 of 8).
It builds on ``linear_light_saturation``: a meter reacts to light the laser adds, which the paper's blend does not
add (its opacity darkens the scene, and a meter would answer by raising the gain).

``frame_exposure`` is the light's ratio to the scene changing from frame to frame. An auto-exposing camera exposes
each *clean* frame for its own scene too (a dark scene longer), while the laser was captured once: a laser of one
power then adds more light, against the clean frame's scale, to a frame exposed longer, by the clean frame's
exposure over the capture's, which no pair records (on the independent simulator's auto-exposure case that ratio
spans 1.6-3.6x over a draw's eight scenes, docs/bench/session68/exposures.txt; with it known, the planted model's
error falls from 10.1-11.5 to 5.8-6.3 grey levels, docs/bench/session68/exposure_oracle.txt). It is a per-frame latent, the laser's gain times ``exp(u)``, ``u`` normal with
standard deviation ``exposure_spread``: fits register ``u`` on each fit frame (they are fit data; the gain is their
geometric mean and the spread their sample deviation), and held-out frames are scored with ``u`` marginalised over
``EXPOSURE_NODES`` equally likely quantiles of that normal (``LatentFrameProblem``), never fitted on the frame.
Registered per frame, ``u`` would also absorb any misfit that differs between frames, so it is the auto-exposure's
(it requires ``auto_exposure``) and named only beside a meter that reacts to the laser as a camera re-exposing every
scene does (``identification_checks``). Fitted on the fit pairs of the independent simulator's glare case (a fixed
exposure), a model with both finds a meter power of 0.015-0.086 and a spread of 0.03-0.18 on four draws, against
1.27-1.80 and 0.41-0.63 on five draws of its auto-exposure case (docs/bench/session68/meter_and_spread_*.txt).

``colour_correction`` is a camera's ISP mixing its raw channels with a colour correction matrix after the sensor
clipped them (consumer cameras' matrices undo the colour filters' overlap: a diagonal above 1, negative
off-diagonals, rows summing to 1). The laser's light then adds and clips in the raw channels, and the matrix takes
the clipped channel's full well, not its light, out of the others; its capture stores its faint channels at 0 (the
matrix pushed them below it), so the laser's raw colour is fitted (``laser_colour_<channel>``, its light there over
its own channel's) and the beam is read from the laser's channel alone, over that channel's share of the mixed
colour. The scene goes to the raw channels by the matrix's inverse (a channel it stored at 0 held an amount the frame
does not record, which this leaves as the inverse reads it). The matrix
has one parameter per raw channel, ``ccm_<channel>``: that channel's light taken out of each of the other two. With
its six off-diagonals free, a calibration on the independent simulator's colour-correcting halo case ran one to its
bound (-1) and withdrew the term; the per-channel form fits all pairs to within 6% of the six (13.13 and 11.94
against 12.35 and 11.33 grey levels, docs/bench/session69/six_offdiagonals.txt, column_form_*.txt). With the
camera's true matrix and tone curve, the laser's true colour takes that case from 41.5 and 35.0 to 17.8 and 14.2
grey levels over all pairs, the capture's colour only to 39.4 and 34.1: the colour is what the capture loses
(docs/bench/session69/ccm_oracle_*.txt).

Through a matrix the frames also see inside the laser channel's saturated core: a fainter raw channel holds ``L
c_j`` until it clips at ``L = 1 / c_j``, tens of times the laser channel's full well, so where the frames are exposed
less than the capture the fainter channels store the beam's profile deep inside the core the capture lost. A spot is
a focused core inside a wider skirt (defocus, a lens's point spread), and a capture saturated out into the skirt
shows only the skirt's edge, whose Gaussian continued inwards misses the core's steeper rise; the matrix's take then
paid for it (camsim's spot, a core with a bloom of 0.15 at 2.5 times its width: on three auto-exposure draws a take
ran to its bound 1, and on its simplest camera the true matrix misfit by 8.0-9.3 grey levels against 2.9 without
the bloom, docs/bench/session94/oracles/). So under ``colour_correction`` the core is continued with a narrower beam
at its centre too (``capture.core_continued``): its peak over the saturated level (``inner_core_log10_peak``) and
width (``inner_core_sigma_ref_px``) are fitted, and the true matrix then fits that camera to 1.8-2.0 grey levels.

That loss is also the matrix's sign, and the term is offered only where the fit pairs' laser captures show it
(``unoffered``): among the beam's lit pixels that did not clip white (the laser's channel stored at >= 128 of 255, some
channel under 250), at least ``MIN_MIXED_SHARE`` store a fainter channel at <= 2. A camera storing its raw channels
keeps a narrowband laser's faint light in proportion there (tens of grey levels); a term fitted without the sign
absorbs other misfits (named on 3 of 6 physical blinding draws of matrix-free cameras, docs/bench/session69.md). On
20 master seeds of the independent simulator's five blinding cases the share is 0.000 on all 100 matrix-free draws
(the faintest channel's median 36-184 grey levels) and above 0.05 on 94 of the same 100 draws with a matrix
(docs/bench/session70/ccm_signature.txt). A laser with no light at all in the other channels would show it without a
matrix; selection then still has to take the term.
"""

from __future__ import annotations

import numpy as np
import torch
from scipy import stats

from lerobot_phantom.calibration.core import Effect, Fit, Param, Problem, fit_least_squares, further_starts
from lerobot_phantom.calibration.frame_models.common import (
    SENSOR_GAMMA,
    FrameProblem,
    LatentFrameProblem,
    Pair,
    ParameterMemo,
    PixelProblem,
    flat_pixels,
    parameter_values,
)
from lerobot_phantom.calibration.tone import (
    CHANNELS,
    CORRECTION_NULLS,
    CORRECTION_PARAMS,
    GAMMA_PARAM,
    SHOULDER_PARAMS,
    TONE_PARAMS,
    correction_matrix,
    decode_encode,
    shoulder_kwargs,
)
from lerobot_phantom.transforms import physics
from lerobot_phantom.transforms.capture import (
    capture_colour,
    core_continued,
    read_capture,
)

# a feature decoded under the tone curve, kept at the fitted point and at a step of each tone parameter for each
# feature tensor a prediction decodes (scene, beam, dark and pattern; the meter's probes likewise): a
# finite-difference column that moves any other parameter decodes the same values again
DECODE_MEMO_SIZE = 2 * (1 + len(TONE_PARAMS)) * 8

BLINDING_EFFECTS = (
    Effect(
        "linear_light_saturation",
        "laser light adds to the scene's light in linear irradiance, the sum clips at the sensor's full well, and "
        "only then is the gamma curve applied - it does not blend the image with the pattern",
    ),
    Effect(
        "halo_power_law",
        "light scattered in the lens and on the sensor spreads glare far around the spot, falling off as a power "
        "of the distance (r^-k) rather than ending with the recorded pattern",
        # glare is light: it adds to the laser's and the scene's irradiance. On a blend it would be the one term
        # that adds light, and fitted there it took over the laser's whole spot (alpha 0) and was named in place
        # of linear_light_saturation (independent simulator, session 12)
        requires=("linear_light_saturation",),
    ),
    Effect(
        "auto_exposure",
        "the camera's auto-exposure reacts to the injected light by lowering its gain, darkening the whole scene "
        "as the laser grows stronger",
        # the meter reads light: on the paper's blend, whose opacity darkens the scene wherever the pattern is dark,
        # it would raise the gain, and fitted there it stood in for light the library has no form for (a lens
        # flare's ghost on the blend: named on 7 of 13 draws, on none once it builds on linear light;
        # docs/bench/session82.md)
        requires=("linear_light_saturation",),
    ),
    SENSOR_GAMMA,
    Effect(
        "tone_shoulder",
        "the camera's tone curve rolls off towards white (a filmic / log-logistic shoulder, calibration/tone.py): "
        "the laser's light and the scene's are stored on a curve far steeper in the shadows and flatter in the "
        "highlights than sRGB, so light added in linear irradiance brightens dark pixels far more than sRGB predicts",
        requires=("linear_light_saturation",),
        # a tone curve, as sensor_gamma is: under a power law of its own the shoulder stops pinning the light's
        # scale and the laser's gain runs to its bound (camsim halo case, docs/bench/camsim_session16.md)
        excludes=("sensor_gamma",),
    ),
    Effect(
        "colour_correction",
        "the camera's ISP mixes its raw channels with a colour correction matrix after the sensor clipped them: the "
        "laser's light adds and clips in the raw channels, the matrix (negative off-diagonals) then takes the "
        "clipped channel's excess out of the others, and the capture's faint channels, pushed below 0, store none "
        "of the laser's colour",
        requires=("linear_light_saturation",),
    ),
    Effect(
        "frame_exposure",
        "the laser's light stands in another ratio to the scene in every frame, by a factor the pair does not "
        "record: an auto-exposing camera exposed each clean frame for its own scene (a dark scene longer), so one "
        "laser power adds more light to some frames than to others",
        requires=("linear_light_saturation", "auto_exposure"),
    ),
)


# the laser gain's top: a spot of ten thousand full wells over a beam-profile capture's unsaturated core
MAX_LOG10_GAIN = 4.0
# frame_exposure: the latent's quantiles a held-out frame is marginalised over (its gain's steps at a spread of 0.4
# are 5-10% near the median), the largest spread searched (a factor of e^3 between frames two deviations apart,
# beyond any scene's range of exposures), and a fit frame's largest registered departure from the median
EXPOSURE_NODES = 12
MAX_EXPOSURE_SPREAD = 1.5
MAX_FRAME_LOG_EXPOSURE = 3.0
# pixels of each frame the exposure meter reads
METER_PROBES = physics.METER_PIXELS
# the least power of the meter's exposure factor (``auto_exposure``) beside which frames' own exposures are named: a
# camera that re-exposes every scene meters the laser's light as a scene's (1 for a uniform meter, more for a
# centre-weighted one and a spot near the centre; half of it for a spot far out in a strongly centre-weighted one)
MIN_METER_REACTION = 0.5
# colour_correction's sign in the laser captures (module docstring): the laser channel's least stored level of a lit
# beam pixel, the level under which no channel clipped white, the most a channel the matrix pushed below 0 stores
# (JPEG's ringing lifts a few to 1-2), and the least share of lit pixels showing it
LIT_STORED = 128 / 255
UNCLIPPED_STORED = 250 / 255
STORED_AT_ZERO = 2.5 / 255
MIN_MIXED_SHARE = 0.05


def faint_channels_at_zero(pattern: torch.Tensor, channel: int) -> tuple[int, int]:
    """(lit beam pixels, those storing a fainter channel at 0) of a laser capture ``pattern`` (3, H, W) in [0, 1]
    whose laser light is in ``channel``: lit is the channel at >= ``LIT_STORED`` with some channel under
    ``UNCLIPPED_STORED``."""
    lit = (pattern[channel] >= LIT_STORED) & (pattern.amin(0) < UNCLIPPED_STORED)
    others = [c for c in range(3) if c != channel]
    at_zero = lit & (pattern[others].amin(0) <= STORED_AT_ZERO)
    return int(lit.sum()), int(at_zero.sum())


def exposure_nodes(spread: float) -> torch.Tensor:
    """The ``EXPOSURE_NODES`` multipliers of the laser's gain a held-out frame is marginalised over, equally likely:
    ``exp(spread z)`` at the standard normal's quantile midpoints."""
    shares = (np.arange(EXPOSURE_NODES) + 0.5) / EXPOSURE_NODES
    return torch.from_numpy(np.exp(spread * stats.norm.ppf(shares)))


def meter_reads(effects: frozenset[str]) -> str:
    """What the meter reads of a pixel's light (``physics.METER_READS``): its luminance where the model holds the
    camera's raw light (``colour_correction``), else the channel mean (module docstring)."""
    return "luminance" if "colour_correction" in effects else "channel_mean"


def inner_core_peak(params: dict):
    """The beam's narrower core's peak over a capture's saturated level (fitted as ``inner_core_log10_peak``)."""
    return 10.0 ** params["inner_core_log10_peak"]


def laser_gain(params: dict):
    """The laser's power in the frames over its power in the recorded pattern (fitted as ``log10_gain``)."""
    return 10.0 ** params["log10_gain"]


# reference pixels from the spot at which the glare's level is fitted: a quarter of the reference frame's side
GLARE_REFERENCE_PX = 64.0
# the glare's inner scale (``physics.power_law_halo``), reference pixels. The halo only lights what the capture did
# not measure, far outside the spot's clipped core, so its inner scale is never seen: fitted, it ran to either end of
# its range (0.3 or 200 px) while the level and exponent fitted the frames as well (camsim halo case,
# docs/bench/camsim_session24.md). Fixed inside the core, the glare is a power law wherever the frames show it
GLARE_INNER_SCALE_REF_PX = 1.0


def laser_level(params: dict, effects: frozenset[str]):
    """The laser's light per unit intensity the frame model scales its pattern by: the gain of a linear-light
    model, the blend's opacity otherwise."""
    return laser_gain(params) if "linear_light_saturation" in effects else params["alpha"]


def halo_amplitude(params: dict):
    """The power-law glare's amplitude at the spot's centre (``physics.power_law_halo``) from its fitted level at
    ``GLARE_REFERENCE_PX``: ``level * (1 + R / GLARE_INNER_SCALE_REF_PX) ** exponent``."""
    return (
        params["halo_level"]
        * (1.0 + GLARE_REFERENCE_PX / GLARE_INNER_SCALE_REF_PX) ** params["halo_exponent"]
    )


class BlindingFrames(LatentFrameProblem, PixelProblem):
    """Pixel-wise blinding models; with ``frame_exposure``, a latent problem (module docstring): the methods below
    score and predict through ``LatentFrameProblem`` for those fits and as a plain ``PixelProblem`` for the rest."""

    attack = "laser_blinding"
    centre_name = "the laser spot"
    base_model = "alpha blend of the scene and the laser pattern (the paper's laser blinding)"
    extended_model = "physical laser injection"
    candidates = BLINDING_EFFECTS
    reads_pattern_dark = True
    # on a filmic camera with auto-exposure, linear light needs both the meter and the tone curve: with either
    # alone it fits no better than the blend, and only the three together do (camsim: 23.7 -> 12.5 grey levels,
    # docs/bench/camsim_session16.md)
    joint_effects = 3
    latent = "each frame's exposure over the laser capture's, in models with frame_exposure (none otherwise)"
    heldout_definition = f"{Problem.heldout_definition}; in models with frame_exposure, {LatentFrameProblem.heldout_definition}"

    def __init__(self, pairs: list[Pair], seed: int) -> None:
        if any(p.pattern is None for p in pairs):
            raise ValueError(
                "laser_blinding frame pairs need a 'pattern' column: a capture of the laser alone (no scene)"
            )
        super().__init__(pairs, seed)
        self.decode_memo = ParameterMemo(DECODE_MEMO_SIZE)
        # each capture read as the physical attack reads one (capture.read_capture), with its dark frame if any
        self.readings = [read_capture(p.pattern, p.pattern_dark) for p in pairs]
        # the pixels the exposure meter reads in each frame, the attack's (physics.meter_pixels), as many in every
        # frame: a frame smaller than METER_PROBES pixels sets the count for all
        self.meter_count = min(METER_PROBES, *(p.height * p.width for p in pairs))
        self.probes = [physics.meter_pixels(p.height, p.width, self.meter_count) for p in pairs]
        self.colours = [capture_colour(p.pattern) for p in pairs]
        # the channel holding most of the captures' laser light: colour_correction reads the beam from it alone
        self.laser_channel = int(torch.stack(self.colours).sum(0).argmax())

        self.probe_features = {
            k: torch.cat([self.features(i, self.probes[i])[k] for i in range(len(pairs))])
            for k in self.features(0, self.probes[0])
        }

    def recording_facts(self) -> dict[str, str]:
        with_frame = sum(p.pattern_dark is not None for p in self.pairs)
        if with_frame == 0:
            source = (
                "the median of the capture's farthest tenth, varying over the frame as the room's linear gradient "
                "read from the capture's part odd about the spot does (one level where too few pixels are "
                "mirrored in the frame; no pattern_dark column)"
            )
        elif with_frame == len(self.pairs):
            source = (
                "the median of the capture's farthest tenth, varying over the frame as a quadratic surface fitted "
                "to its dark frame does (pairs.csv column pattern_dark)"
            )
        else:
            source = (
                f"a dark frame (pattern_dark) for {with_frame} of {len(self.pairs)} pairs, else one level"
            )
        return {"capture_dark_level": source}

    def centre(self, index: int) -> tuple[float, float]:
        return self.readings[index].centre

    def unmeasured(self, index: int, pixels: torch.Tensor | None) -> torch.Tensor:
        """(n, 1): 1 where the capture did not measure the laser's light (below its noise floor), else 0."""
        flat = (~self.readings[index].measured).reshape(-1, 1).double()
        return flat if pixels is None else flat[pixels]

    def features(self, index: int, pixels: torch.Tensor | None) -> dict[str, torch.Tensor]:
        pair = self.pairs[index]
        ys, xs = torch.meshgrid(
            torch.arange(pair.height, dtype=torch.float64),
            torch.arange(pair.width, dtype=torch.float64),
            indexing="ij",
        )
        reading = self.readings[index]
        cx, cy = reading.centre
        radius = (torch.hypot(xs - cx, ys - cy) * pair.to_reference).reshape(-1, 1)
        if pixels is not None:
            radius = radius[pixels]
        n = len(radius)
        return {
            "scene": flat_pixels(pair.clean, pixels),
            "pattern": flat_pixels(pair.pattern, pixels),
            "beam": flat_pixels(reading.beam, pixels),
            "unmeasured": self.unmeasured(index, pixels),
            "dark": flat_pixels(reading.dark, pixels),
            "core_depth": flat_pixels(reading.core_depth, pixels),
            "core_radius": reading.core_radius.reshape(1, 3).expand(n, 3),
            "radius": radius,
            "dark_radius": torch.full((n, 1), reading.dark_radius, dtype=torch.float64),
            "strength": torch.full((n, 1), pair.intensity, dtype=torch.float64),
            "pair": torch.full((n,), index, dtype=torch.long),
            "colour": self.colours[index].reshape(1, 3).expand(n, 3),
            # the laser gain's factor in this frame (frame_exposure's latent; 1 elsewhere)
            "exposure": torch.ones((n, 1), dtype=torch.float64),
        }

    def param_specs(self, effects):
        specs = []
        if "linear_light_saturation" in effects:
            # laser power in the frames over the power the pattern was recorded at: about 1 for a capture at the
            # attack's power, tens to thousands for a beam-profile capture (its core kept unsaturated) of an attack
            # that floods the sensor with many full wells. It spans decades, so it is searched on its logarithm: on
            # a linear 0-200 range a gain of 0.18 sat within 0.1% of the range of 0 and was reported as pinned at
            # its bound (camsim auto-exposure case, docs/bench/camsim_session16.md). The top was 200 until session
            # 37: camsim's halo case draws true gains up to 197, the fits ran into that bound, and a tone shoulder
            # and auto-exposure that camera lacked stretched the light's scale for them (docs/bench/session37.md)
            specs.append(Param("log10_gain", 0.0, -3.0, MAX_LOG10_GAIN, scale=0.5))
            # beam width behind the capture's saturated core (module docstring), reference pixels: from a
            # fraction of a pixel to far wider than the frame (a flat core, held at the full well)
            specs.append(Param("core_sigma_ref_px", 20.0, 0.5, 2000.0, scale=10.0))
        else:
            specs.append(Param("alpha", 0.5, 0.0, 1.0, scale=0.3))
        if "halo_power_law" in effects:
            # the glare's level where the frames show it, at GLARE_REFERENCE_PX from the spot (linear light per
            # unit intensity, 1 = the full well), not its amplitude at the centre: the centre sits in the clipped
            # core, so an amplitude there is unseen and trades against the scale (fitted to the independent
            # simulator it ran to its bound, 50, on every draw)
            specs += [
                Param("halo_level", 0.02, 0.0, 5.0, scale=0.02),
                Param("halo_exponent", 2.0, 0.2, 8.0, scale=1.0),
            ]
        if "auto_exposure" in effects:
            # power of the meter's exposure factor (module docstring): 0 = no reaction; a central spot can
            # weigh several times its area in a centre-weighted meter, hence the range up to 4
            specs.append(Param("auto_exposure", 0.5, 0.0, 4.0, scale=0.5))
        if "sensor_gamma" in effects:
            specs.append(GAMMA_PARAM)
        if "tone_shoulder" in effects:
            specs += list(SHOULDER_PARAMS)
        if "colour_correction" in effects:
            specs += list(CORRECTION_PARAMS)
            # the laser's raw light in each other channel over its own: the capture stores none of it (the matrix
            # pushed those channels below 0), so it is fitted; a narrowband laser holds a few to tens of percent
            specs += [
                Param(
                    f"laser_colour_{CHANNELS[c]}",
                    0.1,
                    0.0,
                    1.0,
                    scale=0.1,
                    low_limit=f"the laser holds no {CHANNELS[c]} light",
                    high_limit=f"the {CHANNELS[c]} channel holds as much laser light as the laser's own",
                )
                for c in range(3)
                if c != self.laser_channel
            ]
            # the beam's focused core inside the skirt whose edge a saturated capture shows (module docstring): the
            # frames' fainter channels measure it through the matrix. Its peak over the saturated level spans
            # decades, so it is searched on its logarithm; at the bottom (1% of the level) it is no light
            specs += [
                Param(
                    "inner_core_log10_peak",
                    1.0,
                    -2.0,
                    4.0,
                    scale=0.5,
                    low_limit="the beam has no core narrower than its saturated edge's Gaussian",
                ),
                Param("inner_core_sigma_ref_px", 10.0, 0.5, 500.0, scale=3.0),
            ]
        if "frame_exposure" in effects:
            # not searched: the sample deviation of the fit frames' registered latents (fit_frame_exposure)
            specs.append(Param("exposure_spread", 0.3, 0.0, MAX_EXPOSURE_SPREAD, scale=0.3))
        return specs

    def null_values(self, effect: str) -> dict[str, float]:
        # the tone curve has no null here: the base composes encoded values, the linear model sRGB
        return {
            "halo_power_law": {"halo_level": 0.0},
            "auto_exposure": {"auto_exposure": 0.0},
            "frame_exposure": {"exposure_spread": 0.0},
            "colour_correction": dict(CORRECTION_NULLS),
        }.get(effect, {})

    @staticmethod
    def tone(effects, params):
        """Power-law tone curve the light is composed in: fitted, sRGB (linear light), or the encoded values (the
        paper); under a fitted shoulder (which excludes ``sensor_gamma``), None: the shoulder has no display gamma."""
        if "sensor_gamma" in effects:
            return params["gamma"]
        return None if "linear_light_saturation" in effects else 1.0

    @classmethod
    def tone_curve(cls, effects, params):
        """(decode, encode) between pixel values and the light the model composes: the fitted log-logistic
        shoulder (``calibration/tone.py``, the convention the noise model reads), else a power law or sRGB."""
        return decode_encode(params, "tone_shoulder" in effects, cls.tone(effects, params))

    def memoised_tone_curve(self, effects, params):
        """:meth:`tone_curve` whose decode is kept per feature tensor and tone curve (``ParameterMemo``)."""
        decode, encode = self.tone_curve(effects, params)
        shoulder = "tone_shoulder" in effects

        def key() -> tuple:
            gamma = self.tone(effects, params)
            return (shoulder, None if gamma is None else float(gamma), *parameter_values(params, TONE_PARAMS))

        return (lambda values: self.decode_memo.get(values, key, lambda: decode(values))), encode

    @staticmethod
    def scene_light(effects, params, f, decode) -> torch.Tensor:
        """The clean scene's light in the channels the model composes in: the stored ones, or under
        ``colour_correction`` the raw ones (the matrix inverted)."""
        scene = decode(f["scene"])
        if "colour_correction" in effects:
            return scene @ torch.linalg.inv(correction_matrix(params)).T
        return scene

    def raw_laser_colour(self, params) -> torch.Tensor:
        """(3,) the laser's raw colour under ``colour_correction``: 1 in its own channel, fitted in the others."""
        return torch.stack(
            [
                torch.ones((), dtype=torch.float64)
                if c == self.laser_channel
                else torch.as_tensor(params[f"laser_colour_{CHANNELS[c]}"], dtype=torch.float64)
                for c in range(3)
            ]
        )

    def compose(self, effects, params, f, decode) -> torch.Tensor:
        """Scene plus laser light (linear in the tone curve ``decode`` inverts), before exposure changes and
        clipping; under ``colour_correction``, in the raw channels (:meth:`compose_raw`)."""
        if "colour_correction" in effects:
            return self.compose_raw(effects, params, f, decode)
        scene = decode(f["scene"])
        s = f["strength"]
        if "linear_light_saturation" in effects:
            laser = core_continued(
                decode(f["beam"]),
                decode(f["dark"]),
                f["core_depth"],
                f["core_radius"],
                params["core_sigma_ref_px"],
            )
            light, scene_weight = s * f["exposure"] * laser_gain(params) * laser, 1.0
        else:
            opacity = (params["alpha"] * s).clamp(0.0, 1.0)
            light, scene_weight = opacity * decode(f["pattern"]), 1.0 - opacity
        if "halo_power_law" in effects:
            # the capture holds the glare, scaled with the beam by the gain, wherever it measured the laser's light,
            # less the glare its dark level took out (read at the dark level's distance). Below its noise floor,
            # the beam's continued edge was fitted to light that held glare too: the two are estimates of one
            # light, the edge's nearer the spot and the glare's beyond, so the larger is taken (their sum counted
            # the glare twice next to the edge, and the fitted glare flattened to make up for it: camsim's halo
            # case named its effects on 12 of 14 master seeds with the larger, 9 with the sum,
            # docs/bench/camsim_session24.md)
            unmeasured = f["unmeasured"] > 0
            glare_at = torch.where(unmeasured, f["radius"], f["dark_radius"])
            halo = physics.power_law_halo(
                glare_at, halo_amplitude(params), params["halo_exponent"], GLARE_INNER_SCALE_REF_PX
            )
            glare = s * f["exposure"] * halo * f["colour"]
            light = torch.where(unmeasured, torch.maximum(light, glare), light + glare)
        return scene_weight * scene + light

    def compose_raw(self, effects, params, f, decode) -> torch.Tensor:
        """Scene plus laser light in the raw channels a colour correction matrix mixes (module docstring). The
        capture's laser channel stores the raw beam times that channel's share of the mixed colour; the beam's raw
        light in every channel is that, over the share, times the laser's fitted raw colour (the glare likewise)."""
        per_stored = physics.raw_light_per_stored(
            correction_matrix(params), self.raw_laser_colour(params), self.laser_channel
        )
        channel = slice(self.laser_channel, self.laser_channel + 1)
        beam = core_continued(
            decode(f["beam"])[:, channel],
            decode(f["dark"])[:, channel],
            f["core_depth"][:, channel],
            f["core_radius"][:, channel],
            params["core_sigma_ref_px"],
            inner_core_peak(params),
            params["inner_core_sigma_ref_px"],
        )
        s = f["strength"]
        light = s * f["exposure"] * laser_gain(params) * beam * per_stored
        if "halo_power_law" in effects:
            # as in compose: the beam's measured light holds the glare, below the capture's floor the larger counts
            unmeasured = f["unmeasured"] > 0
            glare_at = torch.where(unmeasured, f["radius"], f["dark_radius"])
            halo = physics.power_law_halo(
                glare_at, halo_amplitude(params), params["halo_exponent"], GLARE_INNER_SCALE_REF_PX
            )
            glare = s * f["exposure"] * halo * per_stored
            light = torch.where(unmeasured, torch.maximum(light, glare), light + glare)
        return self.scene_light(effects, params, f, decode) + light

    def exposure_factor(self, effects, params, decode, probes: dict | None = None) -> torch.Tensor:
        """Per frame: ``k ** a``, ``k`` the exposure at which the blinded frame meters like the clean one
        (``physics.metered_exposure`` on ``physics.meter_pixels``, as the attack meters). ``probes``: the meter's
        pixels, ``meter_count`` per frame in frame order (default: every pair's, in pair order)."""
        f = self.probe_features if probes is None else probes
        reads = meter_reads(effects)
        total = physics.meter_light(self.compose(effects, params, f, decode), reads, 1)
        scene = physics.meter_light(self.scene_light(effects, params, f, decode), reads, 1)
        return (
            physics.metered_exposure(total.reshape(-1, self.meter_count), scene.reshape(-1, self.meter_count))
            ** params["auto_exposure"]
        )

    def predict_features(self, effects, params, f, probes: dict | None = None):
        """Encoded prediction at the features ``f``; ``f["pair"]`` indexes the frames of ``probes`` (the meter's
        pixels, :meth:`exposure_factor`)."""
        decode, encode = self.memoised_tone_curve(effects, params)
        total = self.compose(effects, params, f, decode)
        if "auto_exposure" in effects:
            total = total * self.exposure_factor(effects, params, decode, probes)[f["pair"]].unsqueeze(1)
        total = total.clamp(0.0, 1.0)
        if "colour_correction" in effects:
            total = (total @ correction_matrix(params).T).clamp(0.0, 1.0)
        return encode(total)

    def probe_slots(self, indices: list[int]) -> dict[str, torch.Tensor]:
        """The meter's pixels of the pairs ``indices`` (repeats kept), as frames 0..len-1 of one probe set."""
        rows = torch.cat([torch.arange(i * self.meter_count, (i + 1) * self.meter_count) for i in indices])
        probes = {k: v[rows] for k, v in self.probe_features.items()}
        probes["pair"] = torch.arange(len(indices)).repeat_interleave(self.meter_count)
        return probes

    def fit(self, effects: frozenset[str], items: np.ndarray, start: Fit | None = None) -> Fit:
        if "frame_exposure" in effects:
            fit = self.fit_frame_exposure(effects, items, start)
        else:
            fit = PixelProblem.fit(self, effects, items, start)
        fit.extra["items"] = np.asarray(items)  # what transform_kwargs reads the attack's options from
        return fit

    def fit_frame_exposure(self, effects: frozenset[str], items: np.ndarray, start: Fit | None) -> Fit:
        """Least squares on the fit frames' pixel samples with each frame's latent ``u`` registered (the first
        frame's held at 0: the gain is free), then the gain moved to their geometric mean and ``exposure_spread``
        set to their sample deviation (module docstring). A resample's repeated frame is registered once per copy."""
        stacked, target = self.stacked_pixels(items, [self.samples[int(i)] for i in items])
        slots = torch.cat(
            [torch.full((len(self.samples[int(i)]),), k, dtype=torch.long) for k, i in enumerate(items)]
        )
        stacked["pair"] = slots
        probes = self.probe_slots([int(i) for i in items])
        names = [f"frame_log_exposure_{k}" for k in range(1, len(items))]
        specs = [s for s in self.param_specs(effects) if s.name != "exposure_spread"] + [
            Param(name, 0.0, -MAX_FRAME_LOG_EXPOSURE, MAX_FRAME_LOG_EXPOSURE, scale=0.3) for name in names
        ]

        def residuals(p):
            latent = torch.stack([torch.zeros((), dtype=torch.float64)] + [p[name] for name in names])
            factor = torch.exp(latent).unsqueeze(1)
            f = {**stacked, "exposure": factor[slots]}
            meter = {**probes, "exposure": factor[probes["pair"]]}
            return (self.predict_features(effects, p, f, meter) - target).ravel()

        params = fit_least_squares(
            specs, residuals, warm=self.warm(start, effects), starts=further_starts(start, effects)
        )
        latent = np.array([0.0] + [params.pop(name) for name in names])
        params["log10_gain"] = float(
            np.clip(params["log10_gain"] + latent.mean() / np.log(10.0), -3.0, MAX_LOG10_GAIN)
        )
        params["exposure_spread"] = (
            float(min(np.std(latent, ddof=1), MAX_EXPOSURE_SPREAD)) if len(latent) > 1 else 0.0
        )
        fit = Fit(effects, params)
        fit.extra["frame_log_exposure"] = (latent - latent.mean()).tolist()
        fit.extra["noise_variance"] = self.noise_variance(fit, items)
        return fit

    def unoffered(self, fit_items: np.ndarray) -> dict[str, str]:
        """``colour_correction`` where the fit pairs' laser captures do not show a matrix (module docstring)."""
        pairs = np.unique(fit_items)
        counts = [faint_channels_at_zero(self.pairs[i].pattern, self.laser_channel) for i in pairs]
        lit, at_zero = (sum(c) for c in zip(*counts, strict=True))
        captures = f"the laser captures of the {len(pairs)} fit pairs (each pair's own)"
        if lit == 0:
            return {
                "colour_correction": f"{captures} hold no lit beam pixel (the {CHANNELS[self.laser_channel]} "
                f"channel stored at >= {LIT_STORED * 255:.0f} with some channel under {UNCLIPPED_STORED * 255:.0f}) "
                "to show a colour correction matrix"
            }
        if at_zero < MIN_MIXED_SHARE * lit:
            return {
                "colour_correction": f"{at_zero} of the {lit} lit beam pixels in {captures} store a fainter channel "
                f"at 0, a share under {MIN_MIXED_SHARE:g}: the camera stores the laser's faint raw light in "
                "proportion, no matrix pushed it below 0"
            }
        return {}

    def identification_checks(self, effect: str, fit: Fit, items: np.ndarray) -> list[str]:
        """A gamma is the camera's tone curve only if it holds near the laser spot and away from it
        (``tone_position_checks``): one that only the pooled frame shows stands for light the library has no form
        for (a lens flare's ghost on the blend was named ``sensor_gamma`` on 5 of 13 draws, docs/bench/session82.md).
        Frames' own exposures are the auto-exposure's: named only where the meter reacts to the laser's light with a
        power of at least ``MIN_METER_REACTION``, as a camera re-exposing every scene does."""
        if effect == "sensor_gamma":
            return self.tone_position_checks(fit, items)
        if effect != "frame_exposure" or fit.params["auto_exposure"] >= MIN_METER_REACTION:
            return []
        return [
            f"the meter reacts to the laser's light with a power of {fit.params['auto_exposure']:.3f}, under "
            f"{MIN_METER_REACTION:g}: a camera that exposes every scene for itself meters the laser's light as a "
            "scene's, so the frames' spread stands for a misfit that differs between frames, not their exposures"
        ]

    def predict_at_nodes(self, fit: Fit, index: int) -> torch.Tensor:
        """(EXPOSURE_NODES, 3, H, W): pair ``index`` predicted at each of the latent's nodes."""
        pair = self.pairs[index]
        f = self.features(index, None)
        probes = self.probe_slots([index])
        out = []
        with torch.no_grad():
            for factor in exposure_nodes(fit.params["exposure_spread"]):
                flat = self.predict_features(
                    fit.effects,
                    fit.params,
                    {
                        **f,
                        "pair": torch.zeros_like(f["pair"]),
                        "exposure": torch.full_like(f["exposure"], factor),
                    },
                    {**probes, "exposure": torch.full_like(probes["exposure"], factor)},
                )
                out.append(flat.T.reshape(3, pair.height, pair.width))
        return torch.stack(out)

    def node_errors(self, fit: Fit, index: int) -> tuple[torch.Tensor, np.ndarray]:
        """(pair ``index`` predicted at each node, each prediction's SSE in [0, 1] units)."""
        predicted = self.predict_at_nodes(fit, index)
        return predicted, ((predicted - self.pairs[index].attacked) ** 2).sum(dim=(1, 2, 3)).numpy()

    def latent_candidates(self, fit: Fit, index: int) -> tuple[np.ndarray, np.ndarray]:
        _, sse = self.node_errors(fit, index)
        return sse, np.full(len(sse), 1.0 / len(sse))

    def predict_registered(self, fit: Fit, index: int) -> torch.Tensor:
        predicted, sse = self.node_errors(fit, index)
        return predicted[int(sse.argmin())]

    # fits without frame_exposure have no latent: scored and predicted as any pixel problem

    def predict_pair(self, fit: Fit, index: int) -> torch.Tensor:
        if "frame_exposure" in fit.effects:
            return LatentFrameProblem.predict_pair(self, fit, index)
        return PixelProblem.predict_pair(self, fit, index)

    def squared_errors(self, fit: Fit, items: np.ndarray) -> tuple[float, int]:
        if "frame_exposure" in fit.effects:
            return LatentFrameProblem.squared_errors(self, fit, items)
        return FrameProblem.squared_errors(self, fit, items)

    def item_squared_errors(self, fit: Fit, items: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        if "frame_exposure" in fit.effects:
            return LatentFrameProblem.item_squared_errors(self, fit, items)
        return Problem.item_squared_errors(self, fit, items)

    # without a latent, a frame's registered and expected errors are its predictive error (the report lists all three)

    def registered_squared_errors(self, fit: Fit, items: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        if "frame_exposure" in fit.effects:
            return LatentFrameProblem.registered_squared_errors(self, fit, items)
        return Problem.item_squared_errors(self, fit, items)

    def expected_squared_errors(self, fit: Fit, items: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        if "frame_exposure" in fit.effects:
            return LatentFrameProblem.expected_squared_errors(self, fit, items)
        return Problem.item_squared_errors(self, fit, items)

    def laser_colour(self, fit: Fit) -> list[float]:
        """The fit frames' laser colour (linear light, its brightest channel 1): the glare's colour."""
        frames = np.unique(fit.extra["items"])
        colour = torch.stack([self.colours[int(i)] for i in frames]).mean(0)
        return (colour / colour.max().clamp(min=1e-9)).tolist()

    def transform_kwargs(self, fit: Fit) -> dict:
        """``LaserBlinding`` options: the paper's alpha levels, or the physical model (``physics.laser_injection``).

        Fed a capture, the physical attack reads it with this model's functions (``capture.read_capture``), continues
        its core at the fitted width and meters with this model's meter, so on a new scene it predicts as the fit
        does: given the pair's dark frame as ``pattern_dark``, it reads the same dark field; it meters the same
        pixels (``physics.meter_pixels``); under ``colour_correction`` it reads the capture's laser channel in the
        fitted raw colour (``raw_colour``)."""
        p, effects = fit.params, fit.effects
        if not effects:
            alpha = min(p["alpha"], 1.0)
            return {"levels": [0.0, alpha / 3, 2 * alpha / 3, alpha]}
        gain = float(laser_level(p, effects))
        # the transform's glare is light per unit of its laser power (intensity times gain), the frame model's per
        # unit intensity (the glare builds on linear light, whose gain is at least 10 ** -3)
        glare = float(halo_amplitude(p)) / gain if "halo_power_law" in effects else 0.0
        return {
            "model": "physical",
            "gain": gain,
            "glare_amplitude": glare,
            "glare_exponent": p.get("halo_exponent", 2.0),
            "glare_scale_ref_px": GLARE_INNER_SCALE_REF_PX,
            **({"color": self.laser_colour(fit)} if "halo_power_law" in effects else {}),
            # the frame model's meter and continued core: the attack reads a capture as the fit read its pairs'
            "meter_power": float(p["auto_exposure"]) if "auto_exposure" in effects else 0.0,
            **({"core_sigma_ref_px": float(p["core_sigma_ref_px"])} if "core_sigma_ref_px" in p else {}),
            "exposure_spread": p["exposure_spread"] if "frame_exposure" in effects else 0.0,
            "colour_correction": correction_matrix(p).reshape(-1).tolist()
            if "colour_correction" in effects
            else None,
            **(
                {
                    "meter_reads": meter_reads(effects),
                    "raw_colour": self.raw_laser_colour(p).tolist(),
                    "inner_core_peak": float(inner_core_peak(p)),
                    "inner_core_sigma_ref_px": float(p["inner_core_sigma_ref_px"]),
                }
                if "colour_correction" in effects
                else {}
            ),
            # tone curve the light was composed in: sRGB (None), fitted, or the encoded values (1.0); a fitted
            # shoulder under its display gamma (None: 1)
            "gamma": self.tone(effects, p),
            **(shoulder_kwargs(p, self.tone(effects, p)) if "tone_shoulder" in effects else {}),
        }
