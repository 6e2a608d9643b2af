"""Light projection: colour-triple tables (surface colour, projected colour -> captured colour).

Base (the paper): the captured colour is an alpha blend of the surface and the projected colour. Physically a
projector's light *adds* to the ambient light, in proportion to what the surface reflects, seen through the
camera's colour filters (cross-talk between primaries), and the sensor saturates.

What a recorded projected colour is comes from the data (``PATTERN_RECORDS``): the frame the projector was sent,
whose light is the projector's own display transfer (``projector_gamma``, fitted with every model in which light
adds), or the projection as the camera captured it, decoded through the camera's tone curve like the scene.

Every model's output is clipped to the file's range (no camera writes more than its white); ``clipping`` is a
sensor that saturates *below* the file's maximum (a white level < 1, e.g. video range or white-balance gains
applied after the raw clip), so saturation exactly at the file's maximum is part of every model and is never
named as a cause.

Frame pairs can show one effect a table cannot: the projected light spread over neighbouring pixels
(``light_spread``). A projector is seldom in focus on every surface it lights, and the camera's lens and
demosaicing spread light further, so a pattern recorded as the frame the projector was sent has sharper edges than
the light in the attacked frame. Light spread across a bright edge is signed (too much predicted on its bright side,
too little on its dark side), so no per-pixel term absorbs it; camsim's optics blur of an emitted pattern hid
clipping under it (docs/bench/session31.md, session32.md).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import torch
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from lerobot_phantom.calibration.core import (
    Effect,
    Fit,
    Param,
    Problem,
    binned_rmse,
    fit_least_squares,
    further_starts,
)
from lerobot_phantom.calibration.structure import NeighbourPairs, ResidualSample
from lerobot_phantom.calibration.tone import (
    CORRECTION_NULLS,
    CORRECTION_PARAMS,
    GAMMA_PARAM,
    SHOULDER_PARAMS,
    correction_matrix,
    implied_gamma_statistic,
    shoulder_curve,
    shoulder_kwargs,
    tone_nulls,
)
from lerobot_phantom.transforms.physics import captured_light_to_raw

TRIPLE_COLUMNS = tuple(f"{k}_{c}" for k in ("origin", "addition", "outcome") for c in "rgb")

# every effect is offered to selection. tone_shoulder is the alternative to sensor_gamma, never both: offered in
# session 4 on top of sensor_gamma, it was selected, then not identified (knee exponent at its bound), and the refit
# without it had lost sensor_gamma. Since session 18 the two forms exclude each other, the richer one (the shoulder)
# must beat the power law by the selection margin, and a form pinned at a bound in most inner folds never takes a
# step (core.forward_select). Measured in docs/bench/camsim_session18.md
EFFECTS = (
    Effect(
        "additive_light",
        "projected light adds to the light already on the surface; it never replaces (blends away) the surface's "
        "own colour",
    ),
    Effect(
        "albedo_modulation",
        "a surface reflects projected light in proportion to its reflectance in each channel, so dark or "
        "strongly coloured surfaces gain less of the projected colour",
        requires=("additive_light",),
    ),
    Effect(
        "channel_crosstalk",
        "the projector's red, green and blue primaries are seen through the camera's overlapping colour filters: "
        "each camera channel picks up a mix of the projected channels (a 3x3 matrix); a property of projected "
        "light, so it builds on additive_light (a blend with a free matrix can dim the surface and add light at "
        "once, which absorbs tone-curve and reflectance effects instead of naming them)",
        requires=("additive_light",),
    ),
    Effect(
        "clipping",
        "the sensor saturates: captured values stop growing at a white level however much light is added",
    ),
    Effect(
        "sensor_gamma",
        "light adds in linear irradiance, but pixel values are gamma-encoded; composing in the encoded values "
        "gets bright additions wrong",
    ),
    Effect(
        "tone_shoulder",
        "the camera's tone curve rolls off towards white (a filmic / log-logistic shoulder, calibration/tone.py): "
        "added light brightens already bright pixels less than a power law predicts",
        excludes=("sensor_gamma",),
        # the curve decodes pixels to linear light, as the power law does: as its knee exponent goes to 0 it is
        # the power law of gamma 1 + shoulder (tone.py), and a power-law camera with shot noise and veiling glare
        # can be fitted better by it (camsim, docs/bench/camsim_session22.md); whether the written curve is a gamma
        # encoding is judged by its equivalent power-law gamma (tone.implied_gamma_statistic)
        implies=("sensor_gamma",),
    ),
)

# frame pairs only: a colour-triple table has no neighbouring pixels for light to spread to
LIGHT_SPREAD = Effect(
    "light_spread",
    "the projected light reaches the sensor spread over neighbouring pixels (a projector out of focus on the "
    "surface, the camera lens's point spread, demosaicing): a pattern recorded as the frame the projector was sent "
    "has sharper edges than the light the camera sees. Modelled as a Gaussian spread of the projected light before "
    "it meets the surface (physics.gaussian_spread); the camera's spread of the scene's own light is already in "
    "the clean frame",
    requires=("additive_light",),
)
# frame pairs only, as measured (docs/bench/session97.md): a colour-triple table could show a matrix too
COLOUR_CORRECTION = Effect(
    "colour_correction",
    "the camera's ISP mixes its raw channels with a colour correction matrix after the sensor: the projected light "
    "meets the surface's reflectance and the sensor's clip in the raw channels, and the matrix (negative "
    "off-diagonals) then mixes them, so a clipped or strongly coloured addition takes light out of the other "
    "stored channels. Where light only adds, the matrix is a change of basis the cross-talk absorbs: it shows "
    "through the reflectance's product and the clip. A pattern captured through the same matrix stores a "
    "primary's fainter channels at black: they hold no raw light of their own (physics.captured_light_to_raw)",
    requires=("additive_light",),
)
FRAME_EFFECTS = (*EFFECTS, LIGHT_SPREAD, COLOUR_CORRECTION)
# the widest spread a fit considers, standard deviation in pixels at the 256-pixel reference (3% of the frame's
# longer side): wider than defocus and lens blur that leave a pattern recognisable, and the fit's kernel grows with it
SPREAD_HIGH_REF_PX = 8.0

CROSSTALK_NAMES = tuple(f"crosstalk_{i}{j}" for i in range(3) for j in range(3))

# a sensor's white bounds every frame it records: clean pixels brighter than a fitted white in all three channels,
# by more than compression and noise move a pixel (grey levels), on more than this share of the clean pixels, say
# the white is not the sensor's
WHITE_EXCEEDED_MARGIN = 3.0
WHITE_EXCEEDED_SHARE = 0.01

# What a recorded projected image is, a fact of the recording that no fit can be left to guess: the frame the
# projector was sent ("emitted": a display's transfer, its EOTF, turns it into light, whatever the camera's tone curve)
# or the projector's light captured by this camera, e.g. on a white board in the dark ("captured": the camera's own
# tone curve decodes it, as it decodes the scene). On a filmic camera (camsim) decoding an emitted frame through the
# camera's curve put a pattern level of one half at 0.04 of white instead of 0.22, and the fit paid for it with a
# hard-clip knee and a reflectance floor at its bound (docs/bench/session76.md)
PATTERN_RECORD_COLUMN = "pattern_record"
PATTERN_RECORDS = {
    "emitted": "the frame the projector was sent: its light is projected ** projector_gamma, the projector's "
    "display transfer, fitted with every model in which projected light adds",
    "captured": "the projector's light as this camera captured it (a board in the dark): decoded through the "
    "camera's tone curve, like the scene",
}


def check_pattern_record(record: str | None, where: str) -> str:
    if record not in PATTERN_RECORDS:
        raise ValueError(
            f"{where}: pattern record {record!r}; valid: "
            + "; ".join(f"{k!r} ({v})" for k, v in PATTERN_RECORDS.items())
        )
    return record


def projection_specs(effects: frozenset[str], pattern_record: str) -> list[Param]:
    specs: list[Param] = []
    additive = "additive_light" in effects
    if not additive:
        specs.append(Param("opacity", 0.3, 0.0, 1.0, scale=0.3))
    elif pattern_record == "emitted":
        # displays' transfers lie near 2.2 (sRGB, BT.1886's 2.4, projectors' bright modes lower): the range only
        # keeps a fit away from a flat or a step response
        specs.append(Param("projector_gamma", 2.2, 0.5, 5.0, scale=1.0))
    if "channel_crosstalk" in effects:
        # a primary's own gain is >= 0 and unbounded in physics (projector power over ambient light): the range
        # only has to be wide enough never to decide a fit; leaks between channels may be negative (colour matrix)
        specs += [
            Param(n, 0.3, 0.0, 50.0, scale=0.3) if n[-2] == n[-1] else Param(n, 0.0, -10.0, 10.0, scale=0.3)
            for n in CROSSTALK_NAMES
        ]
    elif additive:
        specs.append(Param("strength", 0.3, 0.0, 20.0, scale=0.3))
    if "albedo_modulation" in effects:
        # light reflected ~ (surface + floor): a positive floor is light returned whatever the reflectance
        # (specular sheen); a slightly negative one removes the clean frame's veiling glare and black offset,
        # which the projected light is not multiplied by (at most a few percent of full scale). A large floor
        # is the null (no modulation): the range ends where modulation has all but vanished.
        specs.append(Param("reflectance_floor", 0.1, -0.05, 2.0, scale=0.1))
    if "clipping" in effects:
        specs.append(Param("white", 0.95, 0.2, 1.0, scale=0.1))
    if "sensor_gamma" in effects:
        specs.append(GAMMA_PARAM)
    if "tone_shoulder" in effects:
        specs += list(SHOULDER_PARAMS)
    if "light_spread" in effects:
        specs.append(Param("spread_ref_px", 2.0, 0.0, SPREAD_HIGH_REF_PX, scale=1.0))
    if "colour_correction" in effects:
        specs += list(CORRECTION_PARAMS)
    return specs


def projection_nulls(effect: str) -> dict[str, float]:
    """Values at which an effect reduces to the model without it (none for a change of form)."""
    if effect == "channel_crosstalk":  # no camera channel picks up another projected channel
        return {n: 0.0 for n in CROSSTALK_NAMES if n[-2] != n[-1]}
    if effect == "clipping":  # saturation at the file's maximum is in every model
        return {"white": 1.0}
    if effect == "light_spread":
        return {"spread_ref_px": 0.0}
    if effect == "colour_correction":
        return dict(CORRECTION_NULLS)
    return tone_nulls(effect)


def tone_curve(effects, params: dict):
    """(decode, encode) between pixel values and linear light for a model: the fitted shoulder curve, the
    ``sensor_gamma`` power law, or the identity (the paper's composition of encoded values)."""
    gamma = params.get("gamma") if "sensor_gamma" in effects else None
    if "tone_shoulder" in effects:
        curve = shoulder_curve(params, gamma)
        return curve.decode, curve.encode
    if gamma is not None:
        return (lambda v: v.clamp(min=0) ** gamma), (lambda v: v.clamp(min=1e-12) ** (1.0 / gamma))
    return (lambda v: v), (lambda v: v)


def projected_decode(effects, params: dict, channel_dim: int = -1):
    """Projected colour -> the linear light it adds, in the channels it meets the surface in: the projector's
    display transfer where the model has one (an emitted pattern, ``PATTERN_RECORDS``), else the camera's own tone
    curve, and under ``colour_correction`` a captured pattern's light taken to the raw channels
    (``physics.captured_light_to_raw``; ``channel_dim``: the colours' channel dimension)."""
    if "projector_gamma" in params:
        return lambda v: v.clamp(min=0) ** params["projector_gamma"]
    decode = tone_curve(effects, params)[0]
    if "colour_correction" not in effects:
        return decode
    correction = correction_matrix(params)
    return lambda v: captured_light_to_raw(decode(v), v, correction, channel_dim=channel_dim)


def projection_predict(
    surface: torch.Tensor,
    projected: torch.Tensor,
    strength: torch.Tensor,
    effects,
    params: dict[str, float],
    *,
    surface_light: torch.Tensor | None = None,
    projected_light: torch.Tensor | None = None,
) -> torch.Tensor:
    """Captured colour (N, 3) in [0, 1] from surface colour, projected colour (N, 3) and strength (N, 1).
    ``projected_light``: the projected colour already decoded to the light it adds (``projected_decode``, and spread
    over its neighbours, which the caller sees and this function does not), in place of decoding ``projected``;
    ``surface_light`` likewise the surface colour decoded under this model's tone curve."""
    decode, encode = tone_curve(effects, params)
    surface_lin = decode(surface) if surface_light is None else surface_light
    light = projected_decode(effects, params)(projected) if projected_light is None else projected_light
    correction = correction_matrix(params) if "colour_correction" in effects else None
    if correction is not None:  # to the raw channels, where the light meets the reflectance and the clip
        surface_lin = surface_lin @ torch.linalg.inv(correction).T.to(surface_lin.dtype)
    if "channel_crosstalk" in effects:
        matrix = torch.stack(
            [torch.as_tensor(params[n], dtype=surface.dtype) for n in CROSSTALK_NAMES]
        ).reshape(3, 3)
        light = light @ matrix.T
    if "additive_light" in effects:
        light = strength * light * (1.0 if "channel_crosstalk" in effects else params["strength"])
        if "albedo_modulation" in effects:
            light = light * (surface_lin + params["reflectance_floor"]).clamp(min=0.0)
        total = surface_lin + light
    else:
        opacity = params["opacity"] * strength
        total = (1.0 - opacity) * surface_lin + opacity * light
    if "clipping" in effects:
        total = torch.minimum(total, torch.as_tensor(params["white"], dtype=total.dtype))
    if correction is not None:
        total = (total.clamp(min=0.0) @ correction.T.to(total.dtype)).clamp(0.0, 1.0)
    return encode(total).clamp(0.0, 1.0)


def projection_warm(start: Fit | None, effects: frozenset[str]) -> dict[str, float] | None:
    """Start values from a nested fit, mapped to the new model's parameters (a blend's opacity becomes the
    additive strength; a scalar strength seeds the diagonal of a cross-talk matrix; a new colour correction starts
    as the identity, where the model is the nested fit, so the search starts at its optimum: from the default takes a
    cross-talk fitted in the stored channels starts far from it)."""
    if start is None:
        return None
    warm = dict(start.params)
    if "colour_correction" in effects and "colour_correction" not in start.effects:
        warm.update(CORRECTION_NULLS)
    if "additive_light" in effects and "additive_light" not in start.effects:
        opacity = warm.pop("opacity")
        warm["strength"] = opacity
        for name in CROSSTALK_NAMES:
            if name in warm:
                warm[name] *= opacity
    level = warm.get("strength", warm.get("opacity"))
    if level is not None:
        for i in range(3):
            warm.setdefault(f"crosstalk_{i}{i}", level)
    return warm


def projection_kwargs(fit: Fit) -> dict:
    """``LightProjection`` options: the paper's transparency levels, or the physical model (additive light, or
    the blend when only other effects were found) at ``strength`` x intensity."""
    effects, p = fit.effects, fit.params
    if not effects:
        opacity = min(p["opacity"], 1.0)
        return {"levels": [0.0, opacity / 3, 2 * opacity / 3, opacity]}
    additive = "additive_light" in effects
    kwargs: dict = {
        "model": "additive" if additive else "blend",
        "strength": 1.0
        if "channel_crosstalk" in effects and additive
        else p.get("strength", p.get("opacity")),
        "albedo": "albedo_modulation" in effects,
        "reflectance_floor": p.get("reflectance_floor", 0.0),
        "gamma": p.get("gamma", 1.0),
    }
    if "tone_shoulder" in effects:  # the fitted curve itself, under its display gamma
        kwargs.update(shoulder_kwargs(p, kwargs["gamma"]))
    if "channel_crosstalk" in effects:  # builds on additive light: the matrix carries the light's scale
        kwargs["crosstalk"] = [[p[f"crosstalk_{i}{j}"] for j in range(3)] for i in range(3)]
    if "projector_gamma" in p:
        kwargs["projector_gamma"] = p["projector_gamma"]
    if "clipping" in effects:
        kwargs["white"] = p["white"]
    if "light_spread" in effects:
        kwargs["spread"] = p["spread_ref_px"]
    if "colour_correction" in effects:
        kwargs["colour_correction"] = correction_matrix(p).reshape(-1).tolist()
    return kwargs


def nearest_surface_colour(surface: np.ndarray, projected: np.ndarray) -> np.ndarray:
    """For each row, the other row nearest to it in surface colour (Euclidean, over the three channels) among the
    rows under the same projected colour; -1 where no other row has that projected colour. Rows of one object whose
    surface colours nearly agree are pixels of one material lit alike by the room, so under one projected colour a
    model that is right leaves them independent errors; errors that agree say the captured colour depends on the
    inputs in a way the model lacks, or on what those pixels share and the table does not record (where they lie
    in the projector's beam, their angle to it, a glossy surface)."""
    nearest = np.full(len(surface), -1)
    _, group, counts = np.unique(projected, axis=0, return_inverse=True, return_counts=True)
    by_group = np.argsort(group.ravel(), kind="stable")
    for members in np.split(by_group, np.cumsum(counts)[:-1]):
        if len(members) < 2:
            continue
        _, index = cKDTree(surface[members]).query(surface[members], k=2)
        # a row is its own nearest at distance 0; where two rows share a surface colour either may come first
        first_other = np.where(index[:, 0] == np.arange(len(members)), index[:, 1], index[:, 0])
        nearest[members] = members[first_other]
    return nearest


def is_triple_table(columns) -> bool:
    return set(TRIPLE_COLUMNS) <= set(columns)


def check_grey_levels(table: pd.DataFrame, path: Path) -> None:
    """A colour-triple table's colours are 8-bit grey levels (SLAP's format): a number in [0, 255] in every cell of
    ``TRIPLE_COLUMNS``. Colours on a 0-1 scale would read as near black, so they are refused, not read."""
    colours = table[list(TRIPLE_COLUMNS)].apply(pd.to_numeric, errors="coerce").to_numpy(np.float64)
    unread = ~np.isfinite(colours)
    if unread.any():
        row, column = (int(i[0]) for i in np.nonzero(unread))
        raise ValueError(
            f"{path}: colour-triple table has {int(unread.sum())} empty or non-numeric colour cells (first: row "
            f"{row + 1}, {TRIPLE_COLUMNS[column]}); every cell of {list(TRIPLE_COLUMNS)} must be a grey level 0-255"
        )
    low, high = float(colours.min()), float(colours.max())
    if low < 0.0 or high > 255.0:
        raise ValueError(
            f"{path}: colour-triple colours span {low:g}-{high:g}; they must be 8-bit grey levels 0-255 (scale a "
            "16-bit table by 255/65535)"
        )
    if high <= 1.0 and np.any(colours != np.round(colours)):
        raise ValueError(
            f"{path}: colour-triple colours span {low:g}-{high:g}, a 0-1 scale; they must be 8-bit grey levels "
            "0-255 (multiply by 255)"
        )


class ProjectionTerms:
    """Light projection's model terms, shared by colour-triple tables and frame pairs (mixed in before the
    problem class, whose abstract methods these answer)."""

    attack = "light_projection"
    extended_model = "additive projector light"
    candidates = EFFECTS
    # PATTERN_RECORDS' key and where it was read, set by the problem from its data
    pattern_record: str
    pattern_record_source: str

    def recording_facts(self) -> dict[str, str]:
        return {
            "pattern_record": f"{self.pattern_record}: {PATTERN_RECORDS[self.pattern_record]}",
            "pattern_record_source": self.pattern_record_source,
        }

    def param_specs(self, effects: frozenset[str]) -> list[Param]:
        return projection_specs(effects, self.pattern_record)

    def null_values(self, effect: str) -> dict[str, float]:
        return projection_nulls(effect)

    def implied_statistic(
        self, effect: str, implied: str, params: dict[str, float]
    ) -> tuple[str, float, float]:
        return implied_gamma_statistic(effect, implied, params)

    def transform_kwargs(self, fit: Fit) -> dict:
        return projection_kwargs(fit)

    def clean_colours(self, items: np.ndarray) -> torch.Tensor:
        """The unattacked colours (N, 3) in [0, 1] that ``items`` recorded with the same camera."""
        raise NotImplementedError

    def white_exceeded(self, fit: Fit, items: np.ndarray) -> tuple[float, float]:
        """``fit``'s white in grey levels (encoded by its tone curve) and the share of ``items``' clean pixels above
        it in every channel by more than ``WHITE_EXCEEDED_MARGIN``."""
        _, encode = tone_curve(fit.effects, fit.params)
        white = 255.0 * float(encode(torch.tensor(fit.params["white"], dtype=torch.float64)))
        lowest_channel = 255.0 * self.clean_colours(items).min(dim=1).values
        return white, float((lowest_channel > white + WHITE_EXCEEDED_MARGIN).double().mean())

    def identification_checks(self, effect: str, fit: Fit, items: np.ndarray) -> list[str]:
        """``clipping`` is named the sensor's saturation only if the sensor's own clean frames stay under it: the
        camera that recorded the attacked frames recorded the clean ones, so no more than
        ``WHITE_EXCEEDED_SHARE`` of the fit items' clean pixels may exceed the fitted white (encoded by the
        model's tone curve) in every channel by more than ``WHITE_EXCEEDED_MARGIN`` grey levels. Every channel,
        because white-balance gains or a colour matrix applied after the raw clip leave one channel's white above
        another's, but none lifts a pixel's lowest channel over the lowest white. A white below what the camera
        recorded without the attack stands for something that dims bright attacked pixels (an ISP's white balance
        answering the projected cast, camsim's ``white_balance``), not for the sensor."""
        if effect != "clipping":
            return []
        white, share = self.white_exceeded(fit, items)
        if share <= WHITE_EXCEEDED_SHARE:
            return []
        return [
            f"{share:.1%} of the fit items' clean pixels exceed the fitted white ({white:.1f} grey levels) in every "
            f"channel by more than {WHITE_EXCEEDED_MARGIN:g}, over {WHITE_EXCEEDED_SHARE:.0%}: the sensor that "
            "recorded them saturates higher, so the clip is not the sensor's"
        ]


class TripleProblem(ProjectionTerms, Problem):
    input_kind = "colour_triples"
    units = "grey levels (0-255)"
    base_model = "alpha blend of surface and projected colour (the paper's light projection)"
    item_name = "table rows"

    def __init__(self, path: Path, pattern_record: str | None = None) -> None:
        if pattern_record is None:
            self.pattern_record = "emitted"
            self.pattern_record_source = (
                "the table's format: SLAP's addition_r,g,b is the colour the projector emitted"
            )
        else:
            self.pattern_record = check_pattern_record(pattern_record, "--pattern-record")
            self.pattern_record_source = "--pattern-record"
        table = pd.read_csv(path)
        missing = [c for c in TRIPLE_COLUMNS if c not in table.columns]
        if missing:
            raise ValueError(
                f"{path}: colour-triple table lacks columns {missing}; needs {list(TRIPLE_COLUMNS)}"
            )
        check_grey_levels(table, path)
        self.path = path

        def block(kind: str) -> torch.Tensor:
            return torch.tensor(table[[f"{kind}_{c}" for c in "rgb"]].to_numpy(np.float64) / 255.0)

        self.surface, self.projected, self.captured = block("origin"), block("addition"), block("outcome")
        self.strength = torch.ones(len(table), 1, dtype=torch.float64)

    @property
    def n_items(self) -> int:
        return len(self.captured)

    def clean_colours(self, items: np.ndarray) -> torch.Tensor:
        return self.surface[torch.as_tensor(items)]

    def predict(self, fit_effects, params, items) -> torch.Tensor:
        index = torch.as_tensor(items)
        return projection_predict(
            self.surface[index], self.projected[index], self.strength[index], fit_effects, params
        )

    def fit(self, effects: frozenset[str], items: np.ndarray, start: Fit | None = None) -> Fit:
        target = self.captured[torch.as_tensor(items)]
        params = fit_least_squares(
            projection_specs(effects, self.pattern_record),
            lambda p: (self.predict(effects, p, items) - target).ravel(),
            warm=projection_warm(start, effects),
            starts=further_starts(start, effects),
            # a few thousand residuals: exact steps are cheap, and lsmr's took 52 evaluations a fit on the
            # 12-parameter models (cross-talk with the shoulder), 15 of the stop sign's 33 s of CPU
            tr_solver="exact",
        )
        return Fit(effects, params)

    def residual(self, fit: Fit, items: np.ndarray) -> np.ndarray:
        return (
            255.0
            * (self.predict(fit.effects, fit.params, items) - self.captured[torch.as_tensor(items)]).numpy()
        )

    def squared_errors(self, fit: Fit, items: np.ndarray) -> tuple[float, int]:
        r = self.residual(fit, items)
        return float(np.sum(r**2)), r.size

    def item_squared_errors(self, fit: Fit, items: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return (self.residual(fit, items) ** 2).sum(1), np.full(len(items), 3.0)

    def residual_sample(self, fit: Fit, items: np.ndarray, rng: np.random.Generator) -> ResidualSample:
        """Per row: the three channels' residuals against channel, surface and projected level; and each row's
        residual paired with that of the row among ``items`` nearest to it in surface colour under the same
        projected colour (:func:`nearest_surface_colour`; none for a row alone under its projected colour, and
        one pair for two rows that are each other's nearest), clustered by the rows nearest-neighbour links join."""
        r = self.residual(fit, items)
        index = torch.as_tensor(items)
        surface = self.surface[index].numpy() * 255
        projected = self.projected[index].numpy() * 255
        channel = np.broadcast_to(np.arange(3.0), r.shape)
        brightness = np.repeat(projected.sum(1, keepdims=True), 3, 1)
        nearest = nearest_surface_colour(surface, projected)
        linked = nearest >= 0
        graph = coo_matrix(
            (np.ones(int(linked.sum())), (np.flatnonzero(linked), nearest[linked])), shape=(len(nearest),) * 2
        )
        _, cluster = connected_components(graph, directed=False)
        # two rows that are each other's nearest are one pair: kept once, the bootstrap does not count it twice
        order = np.arange(len(nearest))
        nearest[linked & (nearest < order) & (nearest[nearest] == order)] = -1
        none = np.empty(0)
        return ResidualSample(
            list(r),
            {
                "channel": list(channel),
                "surface_level": list(surface),
                "projected_level": list(projected),
                "projected_brightness": list(brightness),
            },
            {
                "nearest_surface_colour": NeighbourPairs(
                    [(row, r[j]) if j >= 0 else (none, none) for row, j in zip(r, nearest, strict=True)],
                    pairing="the residuals of each row and of the row nearest to it in surface colour under the "
                    "same projected colour",
                    groups=[
                        f"projected colour ({', '.join(str(round(v)) for v in colour)})"
                        for colour in projected
                    ],
                    clusters=cluster.tolist(),
                )
            },
        )

    def analyse(self, fit: Fit, items: np.ndarray) -> dict:
        r = self.residual(fit, items)
        index = torch.as_tensor(items)
        surface = self.surface[index].numpy() * 255
        projected = self.projected[index].numpy() * 255
        channel = np.broadcast_to(np.arange(3), r.shape)
        return {
            "channel": binned_rmse(channel, r),
            "projected_level": binned_rmse(projected, r),
            "surface_level": binned_rmse(surface, r),
            "projected_brightness": binned_rmse(np.repeat(projected.sum(1, keepdims=True), 3, 1), r),
        }

    def evidence(self, effect: str, before: Fit, after: Fit, items: np.ndarray) -> str:
        r = self.residual(before, items)
        index = torch.as_tensor(items)
        surface = self.surface[index].numpy()
        projected = self.projected[index].numpy()
        if effect in ("additive_light", "albedo_modulation"):
            driver = surface * projected if effect == "albedo_modulation" else surface
        elif effect == "channel_crosstalk":
            driver = (
                projected[:, [1, 2, 0]] + projected[:, [2, 0, 1]]
            )  # the *other* channels' projected light
        else:
            driver = np.repeat((surface + projected).sum(1, keepdims=True), 3, 1)
        corr = float(np.corrcoef(driver.ravel(), r.ravel())[0, 1]) if np.std(driver) > 0 else 0.0
        return f"before {effect}: residual correlates {corr:+.2f} with its driving variable"

    def figures(self, base: Fit, extended: Fit, items: np.ndarray, out_dir: Path) -> list[str]:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        truth = self.captured[torch.as_tensor(items)].numpy().ravel() * 255
        fig, axes = plt.subplots(1, 2, figsize=(10, 4.5), sharey=True)
        for ax, fit, label in ((axes[0], base, "base (alpha blend)"), (axes[1], extended, "extended")):
            pred = self.predict(fit.effects, fit.params, items).numpy().ravel() * 255
            ax.plot(truth, pred, ".", ms=1, alpha=0.3)
            ax.plot([0, 255], [0, 255], "k-", lw=0.8)
            ax.set(
                xlabel="captured (held-out)",
                title=f"{label}: RMSE {np.sqrt(np.mean((pred - truth) ** 2)):.1f}",
            )
        axes[0].set_ylabel("predicted")
        fig.tight_layout()
        path = out_dir / "triples_measured_vs_predicted.png"
        fig.savefig(path, dpi=100)
        plt.close(fig)
        return [path.name]
