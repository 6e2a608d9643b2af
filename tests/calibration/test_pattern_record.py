"""Light projection's pattern record: a recorded pattern is the frame the projector was sent (``emitted``: the
projector's display transfer makes it light) or the projection as the camera captured it (``captured``: the
camera's own tone curve decodes it). A fact of the recording, never guessed (projection.PATTERN_RECORDS)."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from lerobot_phantom.calibration.cli import CalibrateConfig, build_problem
from lerobot_phantom.calibration.example import write_example
from lerobot_phantom.calibration.frame_models.common import Pair
from lerobot_phantom.calibration.frame_models.light_projection import ProjectionFrames

CAMERA_GAMMA, PROJECTOR_GAMMA = 1.6, 2.4


def emitted_pairs(seed: int, record: str | None = "emitted") -> list[Pair]:
    """Six pairs in numpy: a power-law camera (pixel = light ** (1 / 1.6)) sees a surface lit by a projector whose
    light is the sent frame ** 2.4, 0.6 x intensity strong, with a grey level of noise and 8-bit quantisation."""
    rng = np.random.default_rng(seed)
    pairs = []
    for k in range(6):
        surface = rng.uniform(0.05, 0.5, (3, 24, 32))
        frame = np.zeros((3, 24, 32))
        frame[:, 4:20, 6:26] = rng.choice([0.0, 0.5, 1.0], (3, 1, 1))
        frame[k % 3, 4:20, 6:26] = 0.5 + 0.5 * (k % 2)
        intensity = 0.3 + 0.12 * k
        light = surface + 0.6 * intensity * frame**PROJECTOR_GAMMA
        attacked = np.clip(light, 0, 1) ** (1 / CAMERA_GAMMA) + rng.normal(0.0, 1 / 255, light.shape)
        clean = surface ** (1 / CAMERA_GAMMA)

        def as_u8(image):
            return torch.from_numpy(np.round(np.clip(image, 0, 1) * 255) / 255)

        settings = {} if record is None else {"pattern_record": record}
        pairs.append(Pair(f"p{k}", as_u8(clean), as_u8(attacked), as_u8(frame), intensity, settings))
    return pairs


def test_an_emitted_pattern_is_decoded_by_the_projectors_own_gamma():
    effects = frozenset({"additive_light", "sensor_gamma"})
    items = np.arange(6)
    emitted = ProjectionFrames(emitted_pairs(1), seed=0)
    fit = emitted.fit(effects, items)
    assert fit.params["gamma"] == pytest.approx(CAMERA_GAMMA, abs=0.05)
    assert fit.params["projector_gamma"] == pytest.approx(PROJECTOR_GAMMA, abs=0.1)
    assert emitted.transform_kwargs(fit)["projector_gamma"] == fit.params["projector_gamma"]
    # the same pairs said to be captured: the camera's curve decodes the half-bright frame to the wrong light
    captured = ProjectionFrames(emitted_pairs(1, record="captured"), seed=0)
    wrong = captured.fit(effects, items)
    assert "projector_gamma" not in wrong.params
    emitted_sse, _ = emitted.squared_errors(fit, items)
    captured_sse, _ = captured.squared_errors(wrong, items)
    assert captured_sse > 4 * emitted_sse
    # the paper's blend composes the encoded frame: no projector transfer in it
    assert "projector_gamma" not in emitted.fit(frozenset(), items).params
    assert emitted.recording_facts()["pattern_record_source"] == "pairs.csv column pattern_record"


def test_frame_pairs_that_do_not_say_what_their_patterns_are_are_refused():
    with pytest.raises(
        ValueError, match=r"pattern_record column.*--pattern-record; valid: emitted .* or captured"
    ):
        ProjectionFrames(emitted_pairs(2, record=None), seed=0)
    mixed = emitted_pairs(2)
    mixed[0].settings["pattern_record"] = "captured"
    with pytest.raises(ValueError, match="one value for all pairs"):
        ProjectionFrames(mixed, seed=0)
    with pytest.raises(ValueError, match="contradicts the pairs' pattern_record column"):
        ProjectionFrames(emitted_pairs(2), seed=0, pattern_record="captured")
    with pytest.raises(ValueError, match="valid: 'emitted'"):
        ProjectionFrames(emitted_pairs(2, record="board"), seed=0)
    flagged = ProjectionFrames(emitted_pairs(2, record=None), seed=0, pattern_record="captured")
    assert flagged.pattern_record == "captured"
    assert flagged.recording_facts()["pattern_record_source"] == "--pattern-record"


def test_the_pattern_record_flag_belongs_to_light_projection(tmp_path):
    table = tmp_path / "stripes.csv"
    table.write_text("frequency,exposure_us,duty_cycle,affected_rows_mean,image_height\n100,500,50,30,480\n")
    with pytest.raises(ValueError, match="--pattern-record describes light projection"):
        build_problem(
            CalibrateConfig(attack="laser_color_strip", measured=str(table), pattern_record="emitted")
        )


def test_a_colour_triple_table_is_emitted_by_its_format_unless_told(tmp_path):
    # SLAP's addition_r,g,b is the colour the projector emitted; --pattern-record captured says otherwise
    path = write_example(tmp_path, rows=60)
    additive = frozenset({"additive_light"})
    emitted = build_problem(CalibrateConfig(attack="light_projection", measured=str(path)))
    assert "projector_gamma" in {p.name for p in emitted.param_specs(additive)}
    assert emitted.recording_facts()["pattern_record_source"].startswith("the table's format")
    captured = build_problem(
        CalibrateConfig(attack="light_projection", measured=str(path), pattern_record="captured")
    )
    assert "projector_gamma" not in {p.name for p in captured.param_specs(additive)}
    with pytest.raises(ValueError, match="valid: 'emitted'"):
        build_problem(CalibrateConfig(attack="light_projection", measured=str(path), pattern_record="sent"))
