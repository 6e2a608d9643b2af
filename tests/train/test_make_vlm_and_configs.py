"""make-vlm's offline SmolVLM directory, and the shipped configs (including pi0, which cannot be built here)."""

import re

import pytest
from train_testkit import CONFIGS

from lerobot_phantom.train.make_vlm import IMAGE_TOKENS, VLM_SIZES, main, make_vlm
from lerobot_phantom.train.train import PhantomTrainPipelineConfig

VISION_ATTENTION = ("q_proj", "k_proj", "v_proj", "out_proj")


def test_make_vlm_writes_a_loadable_weightless_smolvlm(tiny_vlm):
    from transformers import AutoConfig, AutoProcessor, AutoTokenizer

    tokenizer = AutoTokenizer.from_pretrained(tiny_vlm)
    # SmolVLA reads these ids off the tokenizer; the processor needs the image tokens to exist.
    for attribute, token in IMAGE_TOKENS.items():
        assert getattr(tokenizer, f"{attribute}_id") == tokenizer.convert_tokens_to_ids(token)
    task = "pick up the red cube\n"
    assert tokenizer.decode(tokenizer(task)["input_ids"]) == task
    # Trained on words and tasks: sub-word pieces, not bytes.
    assert len(tokenizer("pick up the red cube")["input_ids"]) <= len("pick up the red cube") // 2
    config = AutoConfig.from_pretrained(tiny_vlm)
    assert config.vision_config.image_size == VLM_SIZES["tiny"]["image_size"]
    assert config.text_config.vocab_size == len(tokenizer)
    assert AutoProcessor.from_pretrained(tiny_vlm).image_seq_len == 4
    assert not list(tiny_vlm.glob("*.safetensors"))


def test_make_vlm_rejects_bad_size_and_non_empty_out(tmp_path, tiny_vlm):
    with pytest.raises(ValueError, match="tiny"):
        make_vlm(tmp_path / "x", "huge")
    with pytest.raises(FileExistsError):
        make_vlm(tiny_vlm, "tiny")
    with pytest.raises(ValueError, match="--out"):
        main([])


def parse_config(name: str, *args: str) -> PhantomTrainPipelineConfig:
    from lerobot_phantom import _lerobot_compat as compat

    compat.train_script_module()  # registers the policy config types
    return PhantomTrainPipelineConfig.from_pretrained(
        CONFIGS / f"{name}.json", cli_args=["--dataset.repo_id=x", *args]
    )


def test_tiny_config_is_an_offline_cpu_smolvla():
    cfg = parse_config("tiny_smolvla_cpu")
    assert cfg.policy.type == "smolvla" and cfg.policy.device == "cpu"
    assert cfg.policy.load_vlm_weights is False and cfg.peft is None
    # LeRobot's defaults would freeze the weight-free VLM at its random initialisation (issue 11: 3% vs 34% TSR).
    assert cfg.policy.freeze_vision_encoder is False and cfg.policy.train_expert_only is False
    assert list(cfg.policy.resize_imgs_with_padding) == [VLM_SIZES["tiny"]["image_size"]] * 2
    assert cfg.phantom.rate == pytest.approx(0.3) and cfg.phantom.where == "dataloader"


def test_pi0_config_parses_and_its_lora_targets_reach_the_vision_tower():
    """pi0 cannot be built offline; its config parses, and its target regex matches a PaliGemma built here."""
    from transformers import PaliGemmaConfig, PaliGemmaForConditionalGeneration

    cfg = parse_config("pi0_lora_phantom", "--policy.type=pi0")
    assert type(cfg.policy).__name__ == "PI0Config"
    assert cfg.peft.method_type == "LORA" and cfg.phantom.rate == pytest.approx(0.3)
    assert set(cfg.phantom.attacks) == set(
        PhantomTrainPipelineConfig.__dataclass_fields__["phantom"].default_factory().attacks
    )

    tiny = PaliGemmaConfig(
        text_config={
            "hidden_size": 16,
            "intermediate_size": 32,
            "num_hidden_layers": 1,
            "num_attention_heads": 2,
            "num_key_value_heads": 1,
            "head_dim": 8,
            "vocab_size": 64,
        },
        vision_config={
            "hidden_size": 16,
            "intermediate_size": 32,
            "num_hidden_layers": 1,
            "num_attention_heads": 2,
            "image_size": 28,
            "patch_size": 14,
            "projection_dim": 16,
        },
        projection_dim=16,
    )
    # lerobot's PI0Policy holds PaliGemma at model.paligemma_with_expert.paligemma
    names = [
        f"model.paligemma_with_expert.paligemma.{n}"
        for n, _ in PaliGemmaForConditionalGeneration(tiny).named_modules()
    ]
    matched = [n for n in names if re.fullmatch(cfg.peft.target_modules, n)]
    assert {n.rsplit(".", 1)[1] for n in matched if ".vision_tower." in n} == set(VISION_ATTENTION)
    assert any("multi_modal_projector" in n for n in matched)
    assert not any(".language_model." in n for n in matched)  # the VLM's language side stays frozen


def test_smolvla_lora_config_targets_vision_tower_connector_and_expert(tiny_vlm):
    from transformers import AutoConfig, SmolVLMForConditionalGeneration

    cfg = parse_config("smolvla_lora_phantom", "--policy.type=smolvla")
    assert cfg.phantom.where == "device"
    vlm = SmolVLMForConditionalGeneration(AutoConfig.from_pretrained(tiny_vlm))
    names = [f"model.vlm_with_expert.vlm.{n}" for n, _ in vlm.named_modules()]
    names += ["model.vlm_with_expert.lm_expert.layers.0.self_attn.q_proj", "model.action_out_proj"]
    matched = [n for n in names if re.fullmatch(cfg.peft.target_modules, n)]
    assert {n.rsplit(".", 1)[1] for n in matched if ".vision_model." in n} == set(VISION_ATTENTION)
    assert any("connector" in n for n in matched)
    assert "model.vlm_with_expert.lm_expert.layers.0.self_attn.q_proj" in matched
    assert not any(".text_model." in n for n in matched)


def test_make_vlm_patch_size_sets_the_image_token_grid(tmp_path):
    import json

    import torch
    from transformers import AutoConfig, AutoProcessor, SmolVLMModel

    path = make_vlm(tmp_path / "p8", "tiny", patch_size=8)
    config = AutoConfig.from_pretrained(path)
    assert config.vision_config.patch_size == 8
    side = VLM_SIZES["tiny"]["image_size"] // 8 // 2  # the connector folds 2x2 patches into a token
    assert AutoProcessor.from_pretrained(path).image_seq_len == side**2
    assert json.loads((path / "phantom_vlm.json").read_text())["patch_size"] == 8
    model = SmolVLMModel(config).eval()
    size = VLM_SIZES["tiny"]["image_size"]
    with torch.no_grad():
        patches = model.vision_model(pixel_values=torch.zeros(1, 3, size, size)).last_hidden_state
        tokens = model.connector(patches)
    assert tokens.shape[1] == side**2  # 16 tokens per image instead of the 16 px patches' 4
    with pytest.raises(ValueError, match=r"valid: 1, 2, 4, 8, 16, 32"):
        make_vlm(tmp_path / "p5", "tiny", patch_size=5)
    assert not (tmp_path / "p5").exists()
