"""Calibration against an independent camera simulator (issue 12, item 5).

Frame pairs are rendered by ``camsim`` (its own optics, Bayer sensor, noise, tone curve, JPEG and its own physical
form of each attack, never the library's equations) with fresh seeds and parameters every run. Each case plants
named effects (``planted``: the report must name them), may contain effects that are physically present but not the
point of the case (``tolerated``: naming them is not an invention), is a null case (the paper's own digital attack:
the base model must be kept), or hides an effect the library has no name for (the report must not name a cause and
must say that structure is left).

Acceptance (issue 12, "How it will be checked"): planted effects named in >= 90% of the effect cases, at most one
unplanted named cause in any case, null cases keep the base model. The run's master seed is printed in every failure;
``CAMSIM_SEED=<seed>`` replays a run. A run calibrates a share of each kind of case, drawn from the master seed
(``sampled_cases``, tests/sampling.py): ``CAMSIM_CASES=all`` or ``SAMPLED_SHARE=all`` runs the whole matrix.
``CAMSIM_CCM=1`` gives every camera an ISP colour correction matrix (``camsim.random_ccm``), which the library fits
for laser blinding and light projection (``colour_correction``): a measurement, not part of the suite. Its whole
matrix named 17 of 26 effect cases on two master seeds in session 66 (docs/bench/session66.md) and 26 of 32 on two
fresh ones in session 102, four of the six misses light projection's (docs/bench/session102/acceptance_ccm_*.txt).
"""

from __future__ import annotations

import dataclasses
import os
from dataclasses import dataclass, field
from functools import cache
from pathlib import Path

import camsim as cs
import numpy as np
import pytest
import sampling
from scipy.stats import binomtest

from lerobot_phantom.calibration.cli import CalibrateConfig, build_problem, calibrate
from lerobot_phantom.calibration.core import seeded_split
from lerobot_phantom.transforms.registry import make_attack

MASTER_SEED = int(os.environ["CAMSIM_SEED"])  # drawn fresh per run by tests/conftest.py
N_PAIRS = 8
# the bar: planted effects named in at least this share of the effect cases ...
NAMED_SHARE = 0.9
# ... and a run's cases fail it when so few named would happen this rarely at that share: a run draws one or two
# effect cases (tests/sampling.py), whose share alone is 0, 50 or 100%
NAMED_SHARE_ALPHA = 0.05
# effects any physical render contains to some degree: photon noise; and, where light adds in linear irradiance
# under a tone curve that is not a pure power law, a gamma difference
NOISE = frozenset({"shot_noise"})
LINEAR_LIGHT = frozenset({"shot_noise", "sensor_gamma"})
# a filmic camera's tone curve has a highlight shoulder: where light adds in linear irradiance, naming it is true
SHOULDERED_TONES = frozenset({"filmic"})
# a pattern recorded as the frame the projector was sent is sharp, while camsim's optics (its PSF) and demosaicing
# spread the projector's light in the attacked frame: naming that spread is true (a board capture went through the
# same optics, so there the light is recorded spread and naming it is not)
EMITTED_PATTERN = LINEAR_LIGHT | {"light_spread"}


@dataclass(frozen=True)
class Case:
    name: str
    attack: str
    kind: str  # "effect", "null" or "unexplained"
    render: object  # (rng, camera) -> list[FramePair]
    planted: frozenset = frozenset()
    tolerated: frozenset = NOISE
    camera: dict = field(default_factory=dict)


def library_band_profile(cam: cs.Camera) -> np.ndarray:
    """The paper's laser strip band with the constants the library chose (Appendix A gives no sigmas or centre),
    read black-box from the library's transform on a black frame: the null case must be the base model."""
    import torch

    band = make_attack("laser_color_strip", 0.02)(torch.zeros(3, cam.height, cam.width, dtype=torch.uint8))
    band = band.float().amax(dim=0).numpy()
    return band / band.max()


def random_camera(rng: np.random.Generator, **fixed) -> cs.Camera:
    drawn = dict(
        full_well_e=rng.uniform(8000, 30000),
        read_noise_e=rng.uniform(2, 5),
        psf_sigma_px=rng.uniform(0.4, 0.8),
        tone=str(rng.choice(["srgb", "filmic"])),
        jpeg_quality=int(rng.integers(88, 97)),
    )
    if os.environ.get("CAMSIM_CCM") == "1":
        # a measurement, not the suite's default (docs/bench/session66.md): every camera mixes its clipped raw
        # channels with a colour correction matrix, drawn from a stream of its own so that every other draw of the
        # case is the one without it
        drawn["ccm"] = cs.random_ccm(np.random.default_rng(rng.bit_generator.state["state"]["state"]))
    return cs.Camera(**{**drawn, **fixed})


def _gamma_camera(rng):
    # power-law tone curves of real cameras (Rec. 709's 1/0.45, 2.2, legacy 1.8): a gamma near 1 would plant an
    # effect of size zero (gamma 1 is the library's null, composing the encoded values is then exact)
    return {"tone": "power", "tone_gamma": float(rng.uniform(1.8, 2.4))}


CASES = [
    # laser blinding
    Case(
        "blinding_null",
        "laser_blinding",
        "null",
        lambda rng, cam: cs.laser_blinding_pairs(rng, cam, N_PAIRS, digital_alpha=rng.uniform(0.4, 0.8)),
    ),
    Case(
        "blinding_saturation",
        "laser_blinding",
        "effect",
        lambda rng, cam: cs.laser_blinding_pairs(rng, cam, N_PAIRS),
        planted=frozenset({"linear_light_saturation"}),
        tolerated=LINEAR_LIGHT,
    ),
    Case(
        "blinding_auto_exposure",
        "laser_blinding",
        "effect",
        lambda rng, cam: cs.laser_blinding_pairs(rng, cam, N_PAIRS),
        # the camera meters every clean scene too, while the laser was captured once: against each clean frame the
        # laser's light differs by that frame's exposure (1.6-3.6x over a case's scenes, docs/bench/session68.md)
        planted=frozenset({"linear_light_saturation", "auto_exposure", "frame_exposure"}),
        tolerated=LINEAR_LIGHT,
        camera={"auto_exposure": True},
    ),
    Case(
        "blinding_halo",
        "laser_blinding",
        "effect",
        lambda rng, cam: cs.laser_blinding_pairs(rng, cam, N_PAIRS, halo=True),
        planted=frozenset({"linear_light_saturation", "halo_power_law"}),
        tolerated=LINEAR_LIGHT,
    ),
    # light projection
    Case(
        "projection_null",
        "light_projection",
        "null",
        lambda rng, cam: cs.light_projection_pairs(rng, cam, N_PAIRS, digital_alpha=rng.uniform(0.3, 0.6)),
    ),
    Case(
        "projection_additive",
        "light_projection",
        "effect",
        lambda rng, cam: cs.light_projection_pairs(rng, cam, N_PAIRS, power=rng.uniform(0.4, 0.8)),
        planted=frozenset({"additive_light", "albedo_modulation"}),
        tolerated=LINEAR_LIGHT,
    ),
    Case(
        "projection_crosstalk",
        "light_projection",
        "effect",
        # the emitted frame as pattern: a board capture through the same colour filters already holds the
        # cross-talk, which could then not be seen in the pairs at all
        lambda rng, cam: cs.light_projection_pairs(
            rng,
            cam,
            N_PAIRS,
            power=rng.uniform(0.4, 0.8),
            crosstalk=rng.uniform(0.25, 0.4),
            pattern_record="emitted",
        ),
        planted=frozenset({"additive_light", "albedo_modulation", "channel_crosstalk"}),
        tolerated=EMITTED_PATTERN,
    ),
    Case(
        "projection_clipping",
        "light_projection",
        "effect",
        # the emitted frame as pattern: a board capture of a projector bright enough to saturate the camera is
        # itself saturated where the light is strongest, so it records the clip instead of the light. Projector
        # light 6-12x the ambient at full intensity (a bright projector in a dim room): at 3-5x it saturated 0.7%
        # and 2.1% of the pixels (master seeds 27182, 31337), too few for any clip to be seen in a frame's error
        lambda rng, cam: cs.light_projection_pairs(
            rng, cam, N_PAIRS, power=rng.uniform(6.0, 12.0), pattern_record="emitted"
        ),
        planted=frozenset({"additive_light", "albedo_modulation", "clipping"}),
        tolerated=EMITTED_PATTERN,
        # the full well fills 75-92% of the ADC's range (camsim.Camera.well_share_of_adc), so a saturated pixel is
        # written at 225-246 under sRGB. Saturation at the file's maximum (share 1) is in every model: nothing to
        # find. The camera is sRGB because a filmic shoulder writes that headroom within 2 grey levels of the
        # maximum (aces(3.2) / aces(4) = 0.985), a clip no data can show
        camera={"tone": "srgb", "well_share_of_adc": lambda rng: rng.uniform(0.75, 0.92)},
    ),
    Case(
        "projection_sensor_gamma",
        "light_projection",
        "effect",
        # projector light comparable to the ambient light: a weak addition is a small perturbation that any tone
        # curve maps almost linearly (measured: power 0.4-0.8 left the curve 2% of the validation RMSE, at the
        # noise floor; 1.0-1.6 leaves 6-9%)
        lambda rng, cam: cs.light_projection_pairs(rng, cam, N_PAIRS, power=rng.uniform(1.0, 1.6)),
        planted=frozenset({"additive_light", "albedo_modulation", "sensor_gamma"}),
        camera={"tone": "power"},
    ),
    Case(
        "projection_falloff_unnamed",
        "light_projection",
        "unexplained",
        lambda rng, cam: cs.light_projection_pairs(
            rng, cam, N_PAIRS, digital_alpha=rng.uniform(0.4, 0.6), falloff=rng.uniform(0.6, 0.8)
        ),
    ),
    # laser colour strip
    Case(
        "strip_null",
        "laser_color_strip",
        "null",
        lambda rng, cam: cs.laser_strip_pairs(
            rng, cam, N_PAIRS, paper_band=rng.uniform(0.3, 0.6), band_profile=library_band_profile(cam)
        ),
    ),
    Case(
        "strip_overlap",
        "laser_color_strip",
        "effect",
        lambda rng, cam: cs.laser_strip_pairs(rng, cam, N_PAIRS),
        planted=frozenset({"exposure_overlap"}),
        tolerated=LINEAR_LIGHT,
    ),
    Case(
        "strip_period",
        "laser_color_strip",
        "effect",
        lambda rng, cam: cs.laser_strip_pairs(rng, cam, N_PAIRS, multi_stripe=True),
        planted=frozenset({"exposure_overlap", "stripe_period"}),
        tolerated=LINEAR_LIGHT,
    ),
    # EM colour strip
    Case(
        "em_strip_null",
        "em_color_strip",
        "null",
        lambda rng, cam: cs.em_strip_pairs(rng, cam, N_PAIRS, paper_map=True),
    ),
    Case(
        "em_strip_bayer_flip",
        "em_color_strip",
        "effect",
        # the library's bayer_phase_flip is one lost line whose wrong phase runs to the frame's end, and camsim
        # demosaics the moved raw lines (bayer_demosaic; before session 75 the library had only the colour map)
        lambda rng, cam: cs.em_strip_pairs(rng, cam, N_PAIRS, lost_lines="single"),
        planted=frozenset({"bayer_phase_flip", "bayer_demosaic"}),
    ),
    # EM truncation
    Case(
        "truncation_null",
        "em_truncation",
        "null",
        lambda rng, cam: cs.em_truncation_pairs(rng, cam, N_PAIRS),
    ),
    Case(
        "truncation_free_band",
        "em_truncation",
        "effect",
        lambda rng, cam: cs.em_truncation_pairs(rng, cam, N_PAIRS, free_position=True),
        planted=frozenset({"free_band_position"}),
    ),
    Case(
        "truncation_shot_noise",
        "em_truncation",
        "effect",
        lambda rng, cam: cs.em_truncation_pairs(rng, cam, N_PAIRS),
        planted=frozenset({"shot_noise"}),
        # a tone curve without a highlight shoulder (sRGB or a power law). From single exposures, photon and read
        # noise are told apart only through the tone curve's slope (calibration/noise.py), and EM truncation's
        # frames carry nothing about that curve: under an unknown filmic curve any fall of the variance with the
        # signal is a shoulder with read noise as much as one with shot noise. Measured on the previous draw
        # (master seeds 1-12): named on all 6 sRGB cameras (photon noise 91-94% of the residual's variance) and
        # on 4 of 4 power-law cameras replayed from the filmic draws, on none of the 6 filmic ones
        camera={
            "full_well_e": 400.0,
            "read_noise_e": 1.5,
            "jpeg_quality": 97,
            "tone": lambda rng: str(rng.choice(["srgb", "power"])),
            "tone_gamma": lambda rng: float(rng.uniform(1.8, 2.4)),
        },
    ),
    Case(
        "truncation_hum_bars_unnamed",
        "em_truncation",
        "unexplained",
        lambda rng, cam: cs.em_truncation_pairs(rng, cam, N_PAIRS, hum_bars=rng.uniform(0.1, 0.15)),
        # not even photon noise: the bars modulate the light, so the residual's variance grows with its square
        # (named shot_noise on 10 of 10 master seeds until the multiplicative term of session 50, 0 of 10 since:
        # docs/bench/session50.md)
        tolerated=frozenset(),
    ),
    # ultrasound blur
    Case(
        "blur_null",
        "ultrasound_blur",
        "null",
        lambda rng, cam: cs.ultrasound_blur_pairs(rng, cam, N_PAIRS, path="linear"),
    ),
    Case(
        "blur_sinusoidal",
        "ultrasound_blur",
        "effect",
        lambda rng, cam: cs.ultrasound_blur_pairs(rng, cam, N_PAIRS, path="sinusoidal"),
        planted=frozenset({"sinusoidal_motion"}),
        tolerated=LINEAR_LIGHT,
    ),
    Case(
        "blur_rotation_unnamed",
        "ultrasound_blur",
        "unexplained",
        lambda rng, cam: cs.ultrasound_blur_pairs(rng, cam, N_PAIRS, path="rotation"),
    ),
    # appended, so every earlier case keeps its seed under a given master seed
    Case(
        "em_strip_bayer_bands",
        "em_color_strip",
        # bands of rows demosaiced after a lost line (a second one restores the phase): the paper's geometry,
        # the demosaic's form (a null until session 75, when the library had only the paper's colour map)
        "effect",
        lambda rng, cam: cs.em_strip_pairs(rng, cam, N_PAIRS, lost_lines="banded"),
        planted=frozenset({"bayer_demosaic"}),
    ),
    # an effect the library lacks for the three attacks that had none (session 46): the paper's digital forms (the
    # nulls) with a physical effect on top, so all that is left to find is the unnamed one
    Case(
        "blinding_speckle_unnamed",
        "laser_blinding",
        "unexplained",
        lambda rng, cam: cs.laser_blinding_pairs(
            rng, cam, N_PAIRS, digital_alpha=rng.uniform(0.4, 0.8), speckle_looks=int(rng.integers(3, 7))
        ),
        tolerated=frozenset(),  # speckle is the light's own fluctuation (session 50: shot_noise 9 -> 0 of 10)
    ),
    Case(
        "strip_speckle_unnamed",
        "laser_color_strip",
        "unexplained",
        lambda rng, cam: cs.laser_strip_pairs(
            rng,
            cam,
            N_PAIRS,
            paper_band=rng.uniform(0.3, 0.6),
            band_profile=library_band_profile(cam),
            speckle_looks=int(rng.integers(3, 7)),
        ),
        tolerated=frozenset(),  # speckle is the light's own fluctuation (sessions 50-51: shot_noise 8 -> 0 of 16)
    ),
    Case(
        "em_strip_pixel_slip_unnamed",
        "em_color_strip",
        "unexplained",
        lambda rng, cam: cs.em_strip_pairs(
            rng, cam, N_PAIRS, paper_map=True, pixel_slip=int(rng.integers(1, 4))
        ),
        tolerated=frozenset(),  # displaced edges err in proportion to the light (session 50: shot_noise 9 -> 0 of 10)
    ),
    Case(
        "truncation_null_count_spread",
        "em_truncation",
        "null",
        # the count varies from frame to frame (normal, rounded: not the library's uniform floor): still the
        # paper's band start, which a free band must not be named to hedge (session 61; last in the list, so that
        # every other case keeps its case seed)
        lambda rng, cam: cs.em_truncation_pairs(rng, cam, N_PAIRS, count_spread=rng.uniform(0.05, 0.1)),
    ),
    Case(
        "blinding_halo_dark_frame",
        "laser_blinding",
        "effect",
        # blinding_halo with the laser capture repeated with the laser off, which gives the dark room's shape (its
        # gradient, read as one level, is laser light at the gain: docs/bench/session79.md); after the others, so
        # that every case keeps its case seed
        lambda rng, cam: cs.laser_blinding_pairs(rng, cam, N_PAIRS, halo=True, dark_frame=True),
        planted=frozenset({"linear_light_saturation", "halo_power_law"}),
        tolerated=LINEAR_LIGHT,
    ),
    # two effects the library has no name for, first met by session 82's probe (docs/bench/session82.md): the lens
    # out of focus (a disc, an area, where a stabiliser's blur is a path) and the ISP's white balance re-adapting
    # to the projected light's colour cast (every channel of the attacked frame rescaled, none clipped)
    Case(
        "blur_defocus_unnamed",
        "ultrasound_blur",
        "unexplained",
        lambda rng, cam: cs.ultrasound_blur_pairs(rng, cam, N_PAIRS, path="defocus"),
        tolerated=LINEAR_LIGHT,
    ),
    Case(
        "projection_white_balance_unnamed",
        "light_projection",
        "unexplained",
        lambda rng, cam: cs.light_projection_pairs(
            rng, cam, N_PAIRS, digital_alpha=rng.uniform(0.3, 0.6), white_balance=rng.uniform(0.5, 1.0)
        ),
    ),
    # a path swept at constant speed about the rest position (a triangle wave) where a resonance slows to turn at
    # both ends: the library's centred path is a sinusoid's (docs/bench/session84.md)
    Case(
        "blur_triangle_unnamed",
        "ultrasound_blur",
        "unexplained",
        lambda rng, cam: cs.ultrasound_blur_pairs(rng, cam, N_PAIRS, path="triangle"),
        tolerated=LINEAR_LIGHT,
    ),
    Case(
        # the paper's one-way sweep as an exposure records it, in linear irradiance, on a power-law camera: the
        # blur's tone curve planted alone (the resonance only tolerates it)
        "blur_linear_light",
        "ultrasound_blur",
        "effect",
        lambda rng, cam: cs.ultrasound_blur_pairs(rng, cam, N_PAIRS, path="sweep"),
        planted=frozenset({"sensor_gamma"}),
        camera={"tone": "power"},
    ),
]
CASE_BY_NAME = {case.name: case for case in CASES}
# the cases CAMSIM_CASES=core runs: every named frame-pair effect of the library, all six nulls and two unnamed
# effects, with one of the other variants drawn from the master seed (the default before session 60)
CORE = (
    "blinding_null",
    "blinding_auto_exposure",
    "blinding_halo",
    "projection_null",
    "projection_crosstalk",
    "projection_clipping",
    "projection_sensor_gamma",
    "strip_null",
    "strip_period",
    "em_strip_null",
    "em_strip_bayer_flip",
    "truncation_null",
    "truncation_free_band",
    "truncation_shot_noise",
    "truncation_hum_bars_unnamed",
    "blur_null",
    "blur_sinusoidal",
    "blur_rotation_unnamed",
)
KINDS = ("null", "effect", "unexplained")


def sampled_cases_for(master_seed: int, share: float) -> list[str]:
    """A master seed's draw of cases (tests/sampling.py): ``share`` of each kind's cases on average, at least one
    effect case (the naming share is taken over them), in the matrix's order."""
    names = []
    for kind in KINDS:
        of_kind = [c.name for c in CASES if c.kind == kind]
        rng = sampling.group_rng(master_seed, kind)
        names += sampling.draw(of_kind, share, rng, at_least=int(kind == "effect"))
    return [c.name for c in CASES if c.name in names]


def sampled_cases(share: float) -> list[str]:
    """This run's draw of cases, from its master seed."""
    return sampled_cases_for(MASTER_SEED, share)


def selected_cases() -> list[str]:
    """The cases this run calibrates: ``CAMSIM_CASES`` (all, core, sampled or names), by default ``sampled``, at
    ``SAMPLED_SHARE`` (all: every case)."""
    choice = os.environ.get("CAMSIM_CASES", "sampled")
    if choice == "all":
        return [c.name for c in CASES]
    if choice == "sampled":
        return sampled_cases(sampling.share_from_env())
    if choice != "core":
        names = choice.split(",")
        unknown = sorted(set(names) - set(CASE_BY_NAME))
        if unknown:
            raise ValueError(
                f"CAMSIM_CASES: unknown cases {unknown}; valid: all, core, sampled or {sorted(CASE_BY_NAME)}"
            )
        return names
    extras = [c.name for c in CASES if c.name not in CORE]
    extra = extras[np.random.default_rng(MASTER_SEED).integers(len(extras))]
    return [c.name for c in CASES if c.name in CORE or c.name == extra]


SELECTED = selected_cases()


def case_seed(case: Case) -> int:
    index = [c.name for c in CASES].index(case.name)
    return int(np.random.SeedSequence(MASTER_SEED, spawn_key=(index,)).generate_state(1)[0])


def named_causes(report: dict) -> set[str]:
    """Effects the report names as causes: the extended model's (identified) effects and the findings, which
    include shot_noise when the likelihood test keeps it (report schema v2, /work/notes/report-schema.md)."""
    named = set(report["extended"]["effects"]) | {f["effect"] for f in report.get("findings", [])}
    if report.get("noise", {}).get("kept"):
        named.add("shot_noise")
    return named


def named_share_p_value(named: int, cases: int) -> float:
    """The chance of ``named`` or fewer of ``cases`` effect cases named, were each named at the bar's share
    ``NAMED_SHARE`` (a one-sided exact binomial test): a run whose cases had that chance at most
    ``NAMED_SHARE_ALPHA`` is evidence the naming rate is under the bar."""
    return float(binomtest(named, cases, NAMED_SHARE, alternative="less").pvalue)


def unexplained_structure(report: dict) -> str | None:
    """The report's statement that structure is left unexplained, or None when it makes none."""
    structure = report.get("unexplained_structure")
    if not isinstance(structure, dict) or not structure.get("structure_remains"):
        return None
    return structure.get("summary") or "structure remains"


def case_camera(case: Case, seed: int | None = None) -> tuple[int, np.random.Generator, cs.Camera]:
    """The case's seed (``seed``, else this run's), its generator (after the camera's draws; the render draws next)
    and its camera."""
    seed = case_seed(case) if seed is None else seed
    rng = np.random.default_rng(seed)
    overrides = {k: (v(rng) if callable(v) else v) for k, v in case.camera.items()}
    if case.camera.get("tone") == "power":  # a real camera's power law, drawn after the case's own overrides
        overrides.update(_gamma_camera(rng))
    return seed, rng, random_camera(rng, **overrides)


def drawn_split(name: str, case_seed: int, folder):
    """The case's frames at ``case_seed``, read as the calibration CLI reads them, its fit and held-out pairs."""
    case = CASE_BY_NAME[name]
    _, rng, camera = case_camera(case, case_seed)
    cs.write_pairs(folder, case.render(rng, camera))
    cfg = CalibrateConfig(
        attack=case.attack, measured=str(folder), out=str(folder / "out"), seed=case_seed % 2**31
    )
    problem = build_problem(cfg)
    return problem, *seeded_split(problem.n_items, cfg.heldout, cfg.seed)


def drawn_problem(name: str, case_seed: int, folder):
    """The case's frames at ``case_seed``, read as the calibration CLI reads them, and its fit pairs."""
    problem, fit_items, _ = drawn_split(name, case_seed, folder)
    return problem, fit_items


@cache
def run_case(name: str, root: str, seed: int | None = None) -> dict:
    """The case calibrated on its draw of this run (or of case seed ``seed``), kept for the run."""
    case = CASE_BY_NAME[name]
    # the run's own draws keep the case's name (docs/bench/camsim_named_causes.py reads them back by it)
    folder = Path(root) / (name if seed is None else f"{name}_seed{seed}")
    seed, rng, camera = case_camera(case, seed)
    cs.write_pairs(folder / "pairs", case.render(rng, camera))
    report = calibrate(
        CalibrateConfig(
            attack=case.attack, measured=str(folder / "pairs"), out=str(folder / "out"), seed=seed % 2**31
        )
    )
    return {"report": report, "seed": seed, "camera": camera, "out": folder / "out"}


def tolerated(case: Case, camera: cs.Camera) -> frozenset:
    """The effects a case may name besides its planted ones: the case's own, the tone curve's shoulder when the
    camera's curve has one and the case composes light in linear irradiance (the same cases as sensor_gamma), and
    a colour correction where the camera has one and a laser's or a projector's light adds in its raw channels."""
    allowed = case.tolerated
    if camera.tone in SHOULDERED_TONES and "sensor_gamma" in case.tolerated:
        allowed = allowed | {"tone_shoulder"}
    adds_raw_light = {"linear_light_saturation", "additive_light"} & case.planted
    if camera.ccm is not None and case.attack in ("laser_blinding", "light_projection") and adds_raw_light:
        allowed = allowed | {"colour_correction"}
    return allowed


def passes(case: Case, report: dict, camera: cs.Camera) -> bool:
    """A case's verdict over many master seeds (the bench scripts'): an effect case names its planted effects and
    at most one unplanted cause, an unexplained case invents none and reports structure, a null keeps the base.
    ``test_case`` asserts the same per run, except that it leaves the planted effects' naming to the share taken
    over the run's effect cases and reports an unexplained case without structure as an expected failure."""
    named = named_causes(report)
    if case.kind == "effect":
        return case.planted <= named and len(named - case.planted - tolerated(case, camera)) <= 1
    if case.kind == "unexplained":
        return not named - tolerated(case, camera) and bool(unexplained_structure(report))
    return not report["extended"]["effects"]


def replay(case: Case, result: dict) -> str:
    return (
        f"case {case.name} (case seed {result['seed']}); replay with CAMSIM_SEED={MASTER_SEED}; "
        f"camera {result['camera']}"
    )


def test_a_colour_correction_changes_the_camera_and_no_other_draw(monkeypatch):
    plain_rng, ccm_rng = np.random.default_rng(11), np.random.default_rng(11)
    plain = random_camera(plain_rng)
    monkeypatch.setenv("CAMSIM_CCM", "1")
    corrected = random_camera(ccm_rng)
    assert plain.ccm is None and corrected.ccm is not None
    assert dataclasses.replace(corrected, ccm=None) == plain
    assert plain_rng.random() == ccm_rng.random()


def test_a_run_draws_a_share_of_each_kind_of_case_and_at_least_one_effect_case():
    kinds = {kind: [c.name for c in CASES if c.kind == kind] for kind in KINDS}
    assert sampled_cases(1.0) == [c.name for c in CASES]
    counts = {kind: [] for kind in KINDS}
    for seed in range(300):
        drawn = sampled_cases_for(seed, 0.1)
        assert drawn == [c.name for c in CASES if c.name in drawn]  # in the matrix's order
        for kind, names in kinds.items():
            counts[kind].append(len(set(drawn) & set(names)))
    assert min(counts["effect"]) >= 1
    # on average a tenth of each kind (the effect cases' floor of one adds to theirs)
    for kind in ("null", "unexplained"):
        assert np.mean(counts[kind]) == pytest.approx(0.1 * len(kinds[kind]), abs=0.15)
    assert sampled_cases_for(5, 0.1) == sampled_cases_for(5, 0.1)


def test_the_naming_bar_fails_a_run_only_on_evidence_of_a_rate_under_it():
    def fails(named: int, cases: int) -> bool:
        return named_share_p_value(named, cases) <= NAMED_SHARE_ALPHA

    # one effect case, missed, happens in a tenth of runs at the bar: no evidence
    assert named_share_p_value(0, 1) == pytest.approx(0.1)
    assert not fails(0, 1) and not fails(1, 2)
    assert fails(0, 2)  # both missed: 1% of runs at the bar
    # the whole matrix's 16 effect cases: 12 named is 6.8% of runs at the bar, 11 named 1.7%
    assert not fails(12, 16) and fails(11, 16)
    # more named never weighs against the bar
    assert all(named_share_p_value(k, 16) < named_share_p_value(k + 1, 16) for k in range(16))


@pytest.fixture(scope="module")
def root(tmp_path_factory) -> str:
    return str(tmp_path_factory.mktemp("camsim"))


@pytest.mark.slow
@pytest.mark.parametrize("name", SELECTED)
def test_case(name, root):
    case = CASE_BY_NAME[name]
    result = run_case(name, root)
    report = result["report"]
    named = named_causes(report)
    allowed = tolerated(case, result["camera"])
    unplanted = named - case.planted - allowed
    where = replay(case, result)
    if case.attack == "laser_blinding" and result["camera"].ccm is None:
        # a camera without a matrix stores a narrowband laser's faint channels in proportion: its captures never
        # offer the matrix (100 of 100 draws, docs/bench/session70/ccm_signature.txt)
        assert "colour_correction" in report["selection"]["not_offered"], where
    if case.kind == "null":
        assert not report["extended"]["effects"], f"null case gained {report['extended']['effects']}: {where}"
    elif case.kind == "unexplained":
        invented = named - allowed
        assert not invented, f"an effect the library lacks was reported as {sorted(invented)}: {where}"
        if not unexplained_structure(report):
            # open (issue 12): the residual-structure rule misses the unnamed effect on some fresh draws (seen:
            # blur_rotation_unnamed; em_strip_pixel_slip_unnamed on 0 of 11 fresh master seeds until session 46,
            # 8 of 8 since the displacement test of session 47: docs/bench/session47.md); reported as an expected
            # failure with its seed, not hidden
            pytest.xfail(f"no unexplained structure reported: {where}")
    else:
        assert len(unplanted) <= 1, (
            f"unplanted causes {sorted(unplanted)} (planted {sorted(case.planted)}): {where}"
        )


@pytest.mark.slow
def test_photon_noise_is_not_named_where_the_model_leaves_structure_in_the_fit_pairs(root):
    """The hum bars on the draw where photon noise was named beside them (suite run of session 58, master seed
    3527317232): the mean model leaves the bars in the fit pairs' cross-fitted residuals, so the variance law read
    from them is not the sensor's and photon noise is held back, with that reason, by the fit side alone."""
    report = run_case("truncation_hum_bars_unnamed", root, seed=637185383)["report"]
    noise = report["noise"]
    assert not noise["kept"] and "shot_noise" not in named_causes(report)
    assert noise["fit_items_structure"]["structure_remains"]
    assert any("leaves structure in the fit pairs' residuals" in reason for reason in noise["reasons"])
    # conditions 1-4 alone would have named it: the structure is the only reason given beside them
    assert len(noise["reasons"]) == 1


@pytest.mark.slow
def test_a_filmic_cross_talk_draw_names_the_reflectance_it_plants(root):
    """projection_crosstalk on a filmic camera (case seed 279192423, master seed 3044965331 of session 75's matrix,
    where it named light, cross-talk, clipping, spread and a power law; sessions 18-75 missed the reflectance on most
    filmic cameras drawn). The pattern is the frame camsim's projector was sent, whose light is frame ** 2.2: decoded
    through the camera's filmic curve, a half level became a sixth of that light, and the fit ran the shoulder's
    knee to a hard clip and dropped the reflectance. Decoded by the fitted projector gamma (the pairs record their
    pattern as emitted), the written model holds every planted term, the projector gamma near camsim's and the floor
    near full modulation (docs/bench/session76.md)."""
    case = CASE_BY_NAME["projection_crosstalk"]
    result = run_case(case.name, root, seed=279192423)
    assert result["camera"].tone == "filmic"
    report = result["report"]
    named = named_causes(report)
    assert case.planted <= named, replay(case, result)
    assert len(named - case.planted - tolerated(case, result["camera"])) <= 1, replay(case, result)
    assert report["input"]["recording"]["pattern_record"].startswith("emitted")
    intervals = report["extended"]["param_intervals"]
    assert intervals["projector_gamma"]["low"] < 2.2 < intervals["projector_gamma"]["high"]
    assert intervals["reflectance_floor"]["high"] < 0.2
    assert intervals["shoulder_exponent"]["high"] < 4.0
    attack = make_attack("light_projection", calibration=str(result["out"]))
    assert attack.physical["projector_gamma"] == report["extended"]["params"]["projector_gamma"]


@pytest.mark.slow
@pytest.mark.parametrize(
    ("name", "seed"),
    [
        # a null draw that named a free band start (CAMSIM_SEED=1559226399, session 58): one selection fold's line
        # through the counts predicted two frames beyond its intensities a row short, and the band's freedom to
        # start anywhere hedged the missing row (cross-validated 3.43 -> 3.12 grey levels, no held-out gain)
        ("truncation_null", 832276012),
        # a planted free band not named (session 59's draws): two of eight bands start past h - 2n, reaching into
        # the rows the tail repeats, where the free band had no placement, and one frame is unchanged (its band was
        # the tail itself)
        ("truncation_free_band", 3533591311),
    ],
)
def test_em_truncation_draws_that_failed(name, seed, root):
    case = CASE_BY_NAME[name]
    result = run_case(name, root, seed=seed)
    report = result["report"]
    assert set(report["extended"]["effects"]) == set(case.planted), replay(case, result)
    # the calibrated attack runs what was written: the measured line, and the free start where it was named
    attack = make_attack("em_truncation", calibration=str(result["out"]))
    assert attack.ratio_per_intensity == report["extended"]["params"]["ratio_per_intensity"]
    assert attack.free_band_position == ("free_band_position" in case.planted)


def assert_named_with_the_matrix(monkeypatch, root: str, name: str, seed: int) -> dict:
    """The case at case seed ``seed`` on a colour-correcting camera (``CAMSIM_CCM=1``) names its planted causes and
    the matrix, and no cause it does not tolerate. Its ``run_case`` result."""
    monkeypatch.setenv("CAMSIM_CCM", "1")
    case = CASE_BY_NAME[name]
    result = run_case(name, root, seed=seed)
    assert result["camera"].ccm is not None
    named = named_causes(result["report"])
    where = replay(case, result)
    assert case.planted | {"colour_correction"} <= named, where
    assert not named - case.planted - tolerated(case, result["camera"]), where
    return result


@pytest.mark.slow
def test_a_colour_correcting_cameras_blinding_halo_names_the_matrix(monkeypatch, root):
    # session 69: camsim's halo case on a camera mixing its clipped raw channels (CAMSIM_CCM=1, master seed
    # 1834494070, session 66's matrix) named linear light alone, the glare missed and 41 grey levels left over all
    # pairs; the laser's light clips in the raw channels and the matrix takes the clipped channel's excess out of the
    # others, whose capture stores 0 (docs/bench/session69.md)
    result = assert_named_with_the_matrix(monkeypatch, root, "blinding_halo", 1835569645)
    params = result["report"]["extended"]["params"]
    attack = make_attack("laser_blinding", calibration=str(result["out"]))
    matrix = np.reshape(attack.physics.colour_correction, (3, 3))
    assert np.allclose(matrix.sum(1), 1.0)
    assert np.allclose(-matrix[1, 0], params["ccm_red"]) and np.allclose(-matrix[0, 2], params["ccm_blue"])
    # the laser's raw colour, which the attack reads a capture's laser channel in (session 92): red, 1 there
    assert attack.physics.raw_colour == (1.0, params["laser_colour_green"], params["laser_colour_blue"])
    # and the narrower core it continues the capture's saturated core with (session 94)
    assert attack.physics.inner_core_peak == pytest.approx(10 ** params["inner_core_log10_peak"])
    assert attack.physics.inner_core_sigma_ref_px == params["inner_core_sigma_ref_px"]


@pytest.mark.slow
def test_a_colour_correcting_cameras_captured_pattern_names_the_planted_gamma_beside_the_matrix(
    monkeypatch, root
):
    # session 99: camsim's sensor-gamma case on a camera mixing its raw channels (CAMSIM_CCM=1, master seed
    # 2446689515, session 98's matrix) named cross-talk and a shoulder beside the matrix: the pattern, captured on a
    # board through the matrix, stores a primary's fainter channels at black, which the matrix's inverse read back as
    # light the primary never had (physics.captured_light_to_raw; docs/bench/session99.md)
    assert_named_with_the_matrix(monkeypatch, root, "projection_sensor_gamma", 2237660868)


@pytest.mark.slow
def test_planted_effects_are_named(root):
    """The issue's bar, planted effects named in at least 90% of the effect cases, judged on this run's effect
    cases by :func:`named_share_p_value`: a run fails when so few named would happen in at most
    ``NAMED_SHARE_ALPHA`` of runs at that rate. An expected failure (not strict) from session 15 to 101, while the
    rate was under the bar (docs/calibration.md, "Tested against an independent camera simulator"); the whole
    matrix on four master seeds at the package since 149dc4e named 62 of 64 effect cases, 90% interval
    90.5-99.4% (docs/bench/session102/acceptance_pooled_four.txt)."""
    effect_cases = [CASE_BY_NAME[name] for name in SELECTED if CASE_BY_NAME[name].kind == "effect"]
    planted = set().union(*(c.planted for c in effect_cases))
    misses = []
    for case in effect_cases:
        result = run_case(case.name, root)
        named = named_causes(result["report"])
        if not case.planted <= named:
            misses.append(
                f"{case.name}: planted {sorted(case.planted)}, named {sorted(named)} (seed {result['seed']})"
            )
    named_count = len(effect_cases) - len(misses)
    p_value = named_share_p_value(named_count, len(effect_cases))
    assert p_value > NAMED_SHARE_ALPHA, (
        f"planted effects named in {named_count} of {len(effect_cases)} cases (effects {sorted(planted)}): "
        f"p = {p_value:.4f} were {NAMED_SHARE:.0%} of cases named; misses: {misses}; "
        f"replay with CAMSIM_SEED={MASTER_SEED}"
    )
