"""One frame model per camera attack (frame pairs -> calibration problem); the shared part is ``common``."""

from lerobot_phantom.calibration.frame_models.common import FrameProblem, Pair, load_pairs, load_rgb
from lerobot_phantom.calibration.frame_models.em_color_strip import EMStripFrames
from lerobot_phantom.calibration.frame_models.em_truncation import TruncationFrames
from lerobot_phantom.calibration.frame_models.laser_blinding import BlindingFrames
from lerobot_phantom.calibration.frame_models.laser_color_strip import StripFrames
from lerobot_phantom.calibration.frame_models.light_projection import ProjectionFrames
from lerobot_phantom.calibration.frame_models.ultrasound_blur import BlurFrames

FRAME_PROBLEMS = {
    "laser_blinding": BlindingFrames,
    "light_projection": ProjectionFrames,
    "ultrasound_blur": BlurFrames,
    "em_color_strip": EMStripFrames,
    "em_truncation": TruncationFrames,
    "laser_color_strip": StripFrames,
}

__all__ = ["FRAME_PROBLEMS", "FrameProblem", "Pair", "load_pairs", "load_rgb"]
