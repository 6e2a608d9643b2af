"""Adversarial training on LeRobot's own loop: ``lerobot-phantom-train``, the device-side attack step, make-vlm."""

SMOLVLA_VISION_LORA_TARGETS = (
    r"(model\.vlm_with_expert\.lm_expert\..*\.(q|v)_proj"
    r"|model\.(state_proj|action_in_proj|action_out_proj|action_time_mlp_in|action_time_mlp_out)"
    r"|.*\.vision_model\.encoder\.layers\.\d+\.self_attn\.(q|k|v|out)_proj"
    r"|.*\.connector\.modality_projection\.proj)"
)
"""LoRA targets for SmolVLA: LeRobot's expert-only defaults plus the vision tower's attention and the connector
(why: configs/README.md). ``configs/smolvla_lora_phantom.json`` uses the same expression."""
