"""Ultrasound blur frame pairs: a clean frame and the frame blurred by the resonating stabiliser.

Base (the paper's linear blur, Appendix A): sample ``n`` of the path sits ``n`` steps along the displacement, so the
path starts at the pixel and runs one way, a uniform average over ``[0, d]``. A resonance instead oscillates about
the rest position: ``sinusoidal_motion`` is the path ``(d / 2) sin(w t)``, centred, its dwell time arcsine-weighted
toward both turning points. The blur averages light: ``sensor_gamma`` averages it in the linear light of a power
law, ``tone_shoulder`` in that of a tone curve with a highlight shoulder (calibration/tone.py), its alternative.
"""

from __future__ import annotations

import numpy as np
import torch

from lerobot_phantom.calibration.core import Effect, Fit, Param, fit_least_squares
from lerobot_phantom.calibration.frame_models.common import SENSOR_GAMMA, FrameProblem, Pair
from lerobot_phantom.calibration.tone import (
    GAMMA_PARAM,
    SHOULDER_PARAMS,
    TONE_PARAMS,
    decode_encode,
    implied_gamma_statistic,
    shoulder_kwargs,
    tone_nulls,
)
from lerobot_phantom.transforms import physics

PATH_PARAMS = ("dx_ref_px", "dy_ref_px")
# starting paths: lengths (reference pixels) x directions over the whole circle (a one-way path is not its reverse)
PATH_GRID = [
    {"dx_ref_px": length * np.cos(angle), "dy_ref_px": length * np.sin(angle)}
    for length in (2.0, 5.0, 10.0, 20.0, 35.0, 55.0, 80.0)
    for angle in np.arange(24) * np.pi / 12
]
PATH_AGREEMENT_DEG = 20.0  # direction tolerance of a quadrant's path against the whole frame's
PATH_AGREEMENT_SHARE = 0.3  # length tolerance, as a share of the whole frame's path length
# the widest spread across a motion's path, as a share of its length, that the path's own sampling explains
ACROSS_SHARE_LIMIT = 0.5
# the least share of the way from a uniform dwell to the arcsine that a resonance's path must fit: over the
# demosaic's scale (DWELL_LOWPASS_PX) camsim's filmic triangle wave at master seed 2062500564 read 0.106, its hardest
# sweep (docs/bench/session98.md)
DWELL_SHARE_FLOOR = 0.15
# the share of the way from a uniform dwell (0) to the arcsine (1) that a path's samples are read at
DWELL_PARAM = Param("dwell_share", 1.0, 0.0, 1.0, scale=0.1)
# the scale, in pixels of the frames as read, under which the dwell read does not compare them: a clean frame
# carries its camera's demosaic and compression error at its finest scale, and the model blurs that error with the
# scene, while the attacked frame's was made after the blur; a path whose samples spread evenly averages more of it
# away than one whose samples crowd at its ends, so read pixel by pixel a resonance looks like a sweep (camsim,
# master seed 1090987784: 0.000 as drawn, 0.564 without the mosaic, 1.000 without mosaic, JPEG and noise;
# docs/bench/session98.md). Frames are read at their size or smaller (``load_rgb``'s ``max_side``), so a pixel
# as read spans at least one of the camera's
DWELL_LOWPASS_PX = 1.0

BLUR_EFFECTS = (
    Effect(
        "sinusoidal_motion",
        "ultrasound makes the gyroscope resonate, so the stabiliser moves the image sinusoidally about its rest "
        "position: the path is centred on the pixel (not a one-way displacement) and the motion dwells at its "
        "turning points, an arcsine-weighted blur path instead of a uniform line average",
    ),
    SENSOR_GAMMA,
    Effect(
        "tone_shoulder",
        "the camera's tone curve rolls off towards white (a filmic / log-logistic shoulder, calibration/tone.py): "
        "the motion averages light in linear irradiance, and on such a curve a highlight's grey level stands for far "
        "more light than a power law reads from it, so a blurred edge between bright and dark surfaces averages to "
        "grey levels no power law predicts",
        excludes=("sensor_gamma",),
        # a shouldered curve decodes pixels to linear light as the power law does (tone.py): it is a gamma
        # encoding too, judged by its equivalent power-law gamma
        implies=("sensor_gamma",),
    ),
)


def fit_dwell_share(specs: list[Param], errors, held: dict[str, float]) -> float:
    """The dwell share (``DWELL_PARAM``) that, fitted with ``specs``, minimises ``errors``: started from the arcsine
    and from the uniform dwell, the other parameters at ``held``."""
    return fit_least_squares(
        [DWELL_PARAM, *specs],
        errors,
        warm={"dwell_share": 1.0, **held},
        starts=[{"dwell_share": 0.0, **held}],
        jacobian="2-point",
        max_nfev=30,
    )["dwell_share"]


class BlurFrames(FrameProblem):
    attack = "ultrasound_blur"
    base_model = "uniform line average from the pixel along a fitted displacement (the paper's ultrasound blur, linear part)"
    extended_model = "resonant (sinusoidal) motion blur"
    candidates = BLUR_EFFECTS
    taps = 17

    def __init__(self, pairs: list[Pair], seed: int) -> None:
        super().__init__(pairs, seed)
        self._grid_starts: dict[frozenset[str], list[dict[str, float]]] = {}

    def param_specs(self, effects):
        specs = [
            Param("dx_ref_px", 0.0, -64.0, 64.0, scale=4.0),
            Param("dy_ref_px", 0.0, -64.0, 64.0, scale=4.0),
        ]
        if "sensor_gamma" in effects:
            specs.append(GAMMA_PARAM)
        if "tone_shoulder" in effects:
            specs += list(SHOULDER_PARAMS)
        return specs

    def null_values(self, effect: str) -> dict[str, float]:
        return tone_nulls(effect)  # the base blurs the encoded values

    def implied_statistic(
        self, effect: str, implied: str, params: dict[str, float]
    ) -> tuple[str, float, float]:
        return implied_gamma_statistic(effect, implied, params)

    def blur(self, effects, params, index: int) -> torch.Tensor:
        path = "sinusoidal" if "sinusoidal_motion" in effects else "uniform"
        offsets = physics.attack_blur_offsets(path, self.taps, dtype=torch.float64)
        gamma = params["gamma"] if "sensor_gamma" in effects else 1.0
        return self.path_blur(params, index, offsets, gamma, shoulder="tone_shoulder" in effects)

    def path_blur(
        self, params, index: int, offsets: torch.Tensor, gamma, shoulder: bool = False
    ) -> torch.Tensor:
        """Pair ``index``'s clean frame averaged over ``offsets`` (shares of the displacement ``params`` gives at the
        reference scale) in linear light: decoded by the power law ``gamma``, or with ``shoulder`` by the tone curve
        whose shoulder ``params`` holds under that gamma (calibration/tone.py)."""
        pair = self.pairs[index]
        decode, encode = decode_encode(params, shoulder, gamma)
        x = decode(pair.clean.unsqueeze(0))
        scale = pair.intensity / pair.to_reference
        dx = torch.as_tensor(params["dx_ref_px"] * scale, dtype=torch.float64)
        dy = torch.as_tensor(params["dy_ref_px"] * scale, dtype=torch.float64)
        return encode(physics.line_blur(x, dx, dy, offsets))[0]

    def predict_pair(self, fit: Fit, index: int) -> torch.Tensor:
        with torch.no_grad():
            return self.blur(fit.effects, fit.params, index)

    def fit(self, effects: frozenset[str], items: np.ndarray, start: Fit | None = None) -> Fit:
        def residuals(p):
            return torch.cat(
                [(self.blur(effects, p, int(i)) - self.pairs[int(i)].attacked).ravel() for i in items]
            )

        # the blur displacement is far from convex (textures alias): start from the best points of PATH_GRID,
        # scored on a few pairs, besides any nested model's fit
        grid = PATH_GRID
        base = {
            p.name: torch.tensor(p.init, dtype=torch.float64)
            for p in self.param_specs(effects)
            if p.name not in PATH_PARAMS
        }
        probe = items[:3]

        def probe_cost(params):
            return sum(
                float(((self.blur(effects, params, int(i)) - self.pairs[int(i)].attacked) ** 2).sum())
                for i in probe
            )

        # the grid only picks starting points: scored once per model (on pairs of the fit split, which every
        # call during selection draws from), then reused by the folds
        if effects not in self._grid_starts:
            with torch.no_grad():
                costs = [
                    probe_cost({**base, **{k: torch.tensor(v, dtype=torch.float64) for k, v in g.items()}})
                    for g in grid
                ]
            self._grid_starts[effects] = [grid[int(k)] for k in np.argsort(costs)[:2]]
        best = self._grid_starts[effects]
        params = fit_least_squares(
            self.param_specs(effects),
            residuals,
            warm=best[0] if start is None else start.params,
            starts=[best[1] if start is None else best[0]],
            jacobian="2-point",
            max_nfev=30,
        )
        return Fit(effects, params)

    def quadrant_paths(self, fit: Fit, items: np.ndarray) -> list[np.ndarray]:
        """The displacement (dx, dy at the reference scale) fitted on each quadrant of the frames alone, every
        other parameter held at ``fit``'s values and the whole-frame path as the start."""
        specs = [p for p in self.param_specs(fit.effects) if p.name in ("dx_ref_px", "dy_ref_px")]
        held = {
            k: torch.tensor(v, dtype=torch.float64) for k, v in fit.params.items() if k not in PATH_PARAMS
        }
        paths = []
        for top, left in ((0, 0), (0, 1), (1, 0), (1, 1)):

            def errors(p, top=top, left=left):
                parts = []
                for i in items:
                    pair = self.pairs[int(i)]
                    rows = slice(top * pair.height // 2, (top + 1) * pair.height // 2 or None)
                    cols = slice(left * pair.width // 2, (left + 1) * pair.width // 2 or None)
                    error = self.blur(fit.effects, {**held, **p}, int(i)) - pair.attacked
                    parts.append(error[:, rows, cols].ravel())
                return torch.cat(parts)

            # a quadrant's own path may lie in another basin than the whole frame's: also start from the grid
            with torch.no_grad():
                costs = [
                    float(
                        (errors({k: torch.tensor(v, dtype=torch.float64) for k, v in g.items()}) ** 2).sum()
                    )
                    for g in PATH_GRID
                ]
            starts = [PATH_GRID[int(k)] for k in np.argsort(costs)[:2]]
            params = fit_least_squares(
                specs, errors, warm=fit.params, starts=starts, jacobian="2-point", max_nfev=30
            )
            paths.append(np.array([params["dx_ref_px"], params["dy_ref_px"]]))
        return paths

    def across_share(self, fit: Fit, items: np.ndarray) -> float:
        """The width of a uniform spread across ``fit``'s path, as a share of the path's length, that best fits the
        attacked frames of ``items`` when added to the fitted blur (in the same light, every other parameter held)."""
        length = float(np.hypot(fit.params["dx_ref_px"], fit.params["dy_ref_px"]))
        across = np.array([-fit.params["dy_ref_px"], fit.params["dx_ref_px"]]) / max(length, 1e-9)
        decode, encode = decode_encode(
            fit.params, "tone_shoulder" in fit.effects, fit.params.get("gamma", 1.0)
        )
        offsets = physics.blur_path_offsets("uniform", self.taps, dtype=torch.float64)
        with torch.no_grad():
            along = {int(i): decode(self.predict_pair(fit, int(i)).unsqueeze(0)) for i in items}

        def errors(p):
            parts = []
            for i, blurred in along.items():
                pair = self.pairs[i]
                width = p["across_share"] * length * pair.intensity / pair.to_reference
                spread = physics.line_blur(blurred, width * across[0], width * across[1], offsets)
                parts.append((encode(spread)[0] - pair.attacked).ravel())
            return torch.cat(parts)

        # a disc is fitted by a width near its diameter, a motion's sampling by a fraction of that: start from both
        specs = [Param("across_share", 0.1, 0.0, 1.5, scale=0.1)]
        return fit_least_squares(
            specs, errors, starts=[{"across_share": 0.8}], jacobian="2-point", max_nfev=30
        )["across_share"]

    def dwell_share(self, fit: Fit, items: np.ndarray) -> float:
        """Where between a constant-speed sweep (0: uniform dwell) and a sinusoid (1: arcsine dwell) the centred
        path's samples best fit the attacked frames of ``items``: each sample's position interpolated between the
        two, refitted with the path's displacement and the camera's tone curve, a power law with a highlight
        shoulder. The tone curve is free whether or not ``fit`` names it: the blur averages light, and averaged in
        the wrong light a path's ends weigh wrong. A power law alone read a resonance's edges as a uniform dwell
        (docs/bench/session84.md), and on a filmic camera, whose highlights roll off, a uniform sweep as a partly
        turning one (camsim's triangle wave: up to 0.300 with a power law, 0.000 on every filmic draw with the
        shoulder; docs/bench/session85.md). The frames are compared over ``DWELL_LOWPASS_PX``, above the camera's
        demosaic and compression error (docs/bench/session98.md)."""
        return fit_dwell_share(
            self.dwell_specs(),
            lambda p: self.dwell_residuals(p, items, p["dwell_share"]),
            self.dwell_start(fit),
        )

    def dwell_specs(self) -> list[Param]:
        """The parameters refitted with the dwell share: the path and a power law with a highlight shoulder."""
        return [*self.param_specs(frozenset({"sensor_gamma"})), *SHOULDER_PARAMS]

    def dwell_start(self, fit: Fit) -> dict[str, float]:
        """Where the dwell read starts its other parameters: ``fit``'s path and tone curve (a shoulder's under the
        display gamma 1 it was fitted with)."""
        start = {name: fit.params[name] for name in (*PATH_PARAMS, *TONE_PARAMS) if name in fit.params}
        start.setdefault("gamma", 1.0 if "tone_shoulder" in fit.effects else GAMMA_PARAM.init)
        return start

    def dwell_residuals(self, params, items: np.ndarray, share) -> torch.Tensor:
        """The clean frames of ``items`` blurred along the centred path whose samples sit ``share`` of the way from
        a uniform dwell (0) to the arcsine (1), in the shouldered tone curve and path of ``params``
        (``dwell_specs``), minus their attacked frames, smoothed over ``DWELL_LOWPASS_PX``."""
        uniform = physics.blur_path_offsets("uniform", self.taps, dtype=torch.float64)
        arcsine = physics.blur_path_offsets("sinusoidal", self.taps, dtype=torch.float64)
        offsets = (1 - share) * uniform + share * arcsine
        return torch.cat(
            [
                physics.gaussian_spread(
                    (
                        self.path_blur(params, int(i), offsets, params["gamma"], shoulder=True)
                        - self.pairs[int(i)].attacked
                    )[None],
                    DWELL_LOWPASS_PX,
                ).ravel()
                for i in items
            ]
        )

    def identification_checks(self, effect: str, fit: Fit, items: np.ndarray) -> list[str]:
        """A stabiliser moves the whole image along one path, so a resonance is named only if the blur is that:

        - one path for the whole frame: the path fitted on each quadrant alone must agree with the whole frame's,
          within ``PATH_AGREEMENT_DEG`` in direction (modulo 180 degrees for a centred path, which is its own
          reverse) and ``PATH_AGREEMENT_SHARE`` in length (a rotation or a lens-dependent smear does not);
        - a path, not an area: across the path the image moves not at all, so the uniform spread across it that
          best fits the frames on top of the fitted blur (``across_share``) must stay under ``ACROSS_SHARE_LIMIT`` of
          the path's length. The 17 samples of the path leave gaps that a fraction of that width fills (0.05-0.27
          of the length on six draws of camsim's resonance); a blur spread over an area fits a centred path better
          than the one-way path without being a motion (a defocus disc: 0.81-0.87; camsim's rotation: 0.64-1.07;
          docs/bench/session83/across_share_faa5520.txt);
        - a resonance turns: a sinusoid slows to a stop at both ends of its path, so its samples crowd there. Between
          a constant-speed sweep's uniform dwell (0) and the arcsine (1), the dwell that best fits the frames
          (``dwell_share``, the tone curve free) must reach ``DWELL_SHARE_FLOOR``. A resonance of a non-integer
          number of cycles fits a partly uniform dwell. Read over ``DWELL_LOWPASS_PX``, on session 85's 30 draws
          camsim's resonance fits 0.106-1.000 and a centred triangle wave (the same path swept at constant speed)
          0.000-0.065; on 20 fresh draws 0.402-1.000 and 0.000-0.057, where read pixel by pixel the resonance fit
          0.036-0.874 (one draw under the floor of before, 0.1) and the triangle 0.000
          (docs/bench/session98/sinusoid/dwell_lowpass_fresh30.txt, dwell_lowpass_fresh20.txt).
        """
        if effect != "sinusoidal_motion":
            return []
        whole = np.array([fit.params["dx_ref_px"], fit.params["dy_ref_px"]])
        length = float(np.hypot(*whole))
        reasons = []
        share = self.across_share(fit, items)
        if share > ACROSS_SHARE_LIMIT:
            reasons.append(
                f"the blur spreads across its path ({length:.1f} px) by {share:.2f} of its length, more than "
                f"{ACROSS_SHARE_LIMIT:g}: it covers an area, not the path of one motion of the image"
            )
        dwell = self.dwell_share(fit, items)
        if dwell < DWELL_SHARE_FLOOR:
            reasons.append(
                f"the image dwells uniformly along its path (the best-fitting dwell is {dwell:.3f} of the way from a "
                f"constant-speed sweep to a sinusoid's arcsine, under {DWELL_SHARE_FLOOR:g}): it does not slow to "
                "turn at the path's ends as a resonance does"
            )
        for name, path in zip(
            ("top left", "top right", "bottom left", "bottom right"),
            self.quadrant_paths(fit, items),
            strict=True,
        ):
            turn = abs(np.degrees(np.arctan2(path[1], path[0]) - np.arctan2(whole[1], whole[0])))
            turn = min(turn % 180.0, 180.0 - turn % 180.0)
            stretch = abs(float(np.hypot(*path)) - length) / max(length, 1e-9)
            if turn > PATH_AGREEMENT_DEG or stretch > PATH_AGREEMENT_SHARE:
                reasons.append(
                    f"the {name} quadrant's path ({np.hypot(*path):.1f} px at {np.degrees(np.arctan2(path[1], path[0])):.0f} "
                    f"deg) is not the whole frame's ({length:.1f} px at {np.degrees(np.arctan2(whole[1], whole[0])):.0f} deg): "
                    "the blur is not one motion of the image"
                )
        return reasons

    def transform_kwargs(self, fit: Fit) -> dict:
        """``UltrasoundBlur`` options: the fitted displacement at intensity 1 (reference pixels of the longer side,
        as the fit scales it), the path's shape and the light it is averaged in."""
        kwargs: dict = {"displacement_per_intensity_px": [fit.params[name] for name in PATH_PARAMS]}
        if "sinusoidal_motion" in fit.effects:
            kwargs["path"] = "sinusoidal"
        if "sensor_gamma" in fit.effects:
            kwargs["gamma"] = fit.params["gamma"]
        if "tone_shoulder" in fit.effects:
            kwargs.update(shoulder_kwargs(fit.params))
        return kwargs

    def derived(self, fit: Fit) -> dict:
        dx, dy = fit.params["dx_ref_px"], fit.params["dy_ref_px"]
        return {
            "blur_length_ref_px_at_intensity_1": float(np.hypot(dx, dy)),
            "direction_deg": float(np.degrees(np.arctan2(dy, dx))),
        }
