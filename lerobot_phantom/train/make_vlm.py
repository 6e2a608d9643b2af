"""``lerobot-phantom-make-vlm``: a local SmolVLM-architecture directory, so SmolVLA trains with no hub.

SmolVLA builds its backbone from ``--policy.vlm_model_name`` (config + processor) and tokenizes tasks with
``AutoTokenizer.from_pretrained(vlm_model_name)``. This writes exactly those files - a small ``SmolVLMConfig``, a
byte-level BPE tokenizer trained here on a built-in word list plus the caller's task strings, and the SmolVLM
image/video processor configs - and no weights, so it is used with ``--policy.load_vlm_weights=false``::

    lerobot-phantom-make-vlm --out=outputs/tiny_vlm --size=tiny
    lerobot-phantom-train --policy.type=smolvla --policy.vlm_model_name=outputs/tiny_vlm \\
        --policy.load_vlm_weights=false --policy.resize_imgs_with_padding='[64,64]' ...

The image side must see ``resize_imgs_with_padding`` equal to the directory's ``image_size`` (printed and stored in
``phantom_vlm.json``).
"""

from __future__ import annotations

import itertools
import json
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import draccus

# Architecture sizes. "tiny" is for CPU tests (seconds per step); "small" for CPU demos that should learn a little.
VLM_SIZES: dict[str, dict[str, int]] = {
    "tiny": {
        "text_hidden": 64,
        "text_layers": 2,
        "text_heads": 4,
        "text_kv_heads": 2,
        "vision_hidden": 32,
        "vision_layers": 1,
        "vision_heads": 2,
        "image_size": 64,
        "patch_size": 16,
        "vocab_size": 512,
    },
    "small": {
        "text_hidden": 256,
        "text_layers": 4,
        "text_heads": 4,
        "text_kv_heads": 2,
        "vision_hidden": 128,
        "vision_layers": 2,
        "vision_heads": 4,
        "image_size": 128,
        "patch_size": 16,
        "vocab_size": 2048,
    },
}

# Pixel-shuffle factor of SmolVLM's connector: image_size / patch_size must be divisible by it.
SCALE_FACTOR = 2

# Special tokens that SmolVLM's processor and SmolVLA's model look up by attribute on the tokenizer.
PAD_TOKEN = "<|endoftext|>"
BOS_TOKEN = "<|im_start|>"
EOS_TOKEN = "<end_of_utterance>"
IMAGE_TOKENS = {
    "fake_image_token": "<fake_token_around_image>",
    "image_token": "<image>",
    "end_of_utterance_token": EOS_TOKEN,
    "global_image_token": "<global-img>",
}

# Everyday manipulation vocabulary, so that tasks not passed at build time still tokenize into few pieces.
WORD_LIST = [
    "a",
    "an",
    "the",
    "this",
    "that",
    "these",
    "those",
    "it",
    "its",
    "of",
    "to",
    "in",
    "into",
    "on",
    "onto",
    "from",
    "off",
    "at",
    "by",
    "with",
    "without",
    "and",
    "or",
    "then",
    "next",
    "after",
    "before",
    "until",
    "while",
    "up",
    "down",
    "left",
    "right",
    "top",
    "bottom",
    "front",
    "back",
    "behind",
    "near",
    "far",
    "inside",
    "outside",
    "over",
    "under",
    "between",
    "beside",
    "above",
    "below",
    "middle",
    "center",
    "corner",
    "edge",
    "side",
    "pick",
    "place",
    "put",
    "move",
    "push",
    "pull",
    "lift",
    "drop",
    "grasp",
    "grab",
    "release",
    "hold",
    "open",
    "close",
    "turn",
    "rotate",
    "slide",
    "stack",
    "unstack",
    "insert",
    "remove",
    "take",
    "give",
    "bring",
    "fetch",
    "pour",
    "fill",
    "empty",
    "wipe",
    "clean",
    "fold",
    "unfold",
    "press",
    "stop",
    "wait",
    "go",
    "reach",
    "hand",
    "cube",
    "block",
    "box",
    "bowl",
    "cup",
    "mug",
    "plate",
    "dish",
    "bottle",
    "can",
    "jar",
    "lid",
    "drawer",
    "door",
    "cabinet",
    "shelf",
    "table",
    "tray",
    "basket",
    "bin",
    "sponge",
    "towel",
    "cloth",
    "ball",
    "peg",
    "hole",
    "ring",
    "stick",
    "tool",
    "spoon",
    "fork",
    "knife",
    "pan",
    "pot",
    "kettle",
    "button",
    "switch",
    "handle",
    "knob",
    "red",
    "green",
    "blue",
    "yellow",
    "orange",
    "purple",
    "pink",
    "black",
    "white",
    "gray",
    "grey",
    "brown",
    "small",
    "large",
    "big",
    "little",
    "tall",
    "short",
    "long",
    "first",
    "second",
    "third",
    "one",
    "two",
    "three",
    "four",
    "five",
    "all",
    "each",
    "both",
    "other",
    "another",
    "same",
    "different",
    "robot",
    "arm",
    "gripper",
    "camera",
    "laser",
    "light",
    "sound",
    "voice",
    "attack",
    "clean",
    "safe",
    "careful",
    "slowly",
    "quickly",
    "carefully",
    "do",
    "not",
    "please",
    "now",
    "again",
    "here",
    "there",
    "what",
    "which",
    "where",
    "how",
]


def tiny_vlm_corpus(tasks: Sequence[str] = ()) -> list[str]:
    """Training text for the tokenizer: the word list (alone and in pairs) plus the tasks."""
    lines = list(WORD_LIST)
    lines += [f"{a} {b}" for a, b in itertools.pairwise(WORD_LIST)]
    lines += [str(t) for t in tasks]
    return lines


def _train_tokenizer(vocab_size: int, tasks: Sequence[str]):
    from tokenizers import Tokenizer, decoders, models, pre_tokenizers, trainers
    from transformers import PreTrainedTokenizerFast

    specials = [PAD_TOKEN, BOS_TOKEN, *dict.fromkeys(IMAGE_TOKENS.values())]
    backend = Tokenizer(models.BPE())
    # Byte-level: any text (including spoofed instructions) encodes without unknown tokens.
    backend.pre_tokenizer = pre_tokenizers.ByteLevel(add_prefix_space=False)
    backend.decoder = decoders.ByteLevel()
    trainer = trainers.BpeTrainer(
        vocab_size=vocab_size,
        special_tokens=specials,
        initial_alphabet=pre_tokenizers.ByteLevel.alphabet(),
        show_progress=False,
    )
    backend.train_from_iterator(tiny_vlm_corpus(tasks), trainer)
    return PreTrainedTokenizerFast(
        tokenizer_object=backend,
        bos_token=BOS_TOKEN,
        eos_token=EOS_TOKEN,
        pad_token=PAD_TOKEN,
        unk_token=PAD_TOKEN,
        model_input_names=["input_ids", "attention_mask"],
        extra_special_tokens=IMAGE_TOKENS,
    )


def valid_patch_sizes(image_size: int) -> list[int]:
    """Patch sizes whose patch grid the connector's pixel shuffle can fold: divisors of ``image_size / SCALE_FACTOR``."""
    return [p for p in range(1, image_size // SCALE_FACTOR + 1) if image_size % (p * SCALE_FACTOR) == 0]


def make_vlm(
    out: str | Path, size: str = "tiny", tasks: Sequence[str] = (), patch_size: int | None = None
) -> Path:
    """Write a weightless SmolVLM directory (config, tokenizer, processors) to ``out``; return its path.

    ``patch_size`` overrides the size's (16): the vision tower cuts the image into ``(image_size / patch_size)^2``
    patches and the connector folds each 2x2 block into one token, so at 128 px a patch of 8 gives 64 image tokens
    per camera instead of 16 (each token then covers 16x16 pixels of the padded frame instead of 32x32).
    """
    from transformers import SmolVLMConfig, SmolVLMImageProcessor, SmolVLMProcessor, SmolVLMVideoProcessor

    if size not in VLM_SIZES:
        raise ValueError(f"--size must be one of {sorted(VLM_SIZES)}, got {size!r}")
    dims = dict(VLM_SIZES[size])
    if patch_size is not None:
        valid = valid_patch_sizes(dims["image_size"])
        if patch_size not in valid:
            raise ValueError(
                f"--patch_size {patch_size} does not divide a {dims['image_size']} px image into a patch grid "
                f"the connector can fold by {SCALE_FACTOR}; valid: {', '.join(map(str, valid))}"
            )
        dims["patch_size"] = patch_size
    out = Path(out)
    if out.exists() and any(out.iterdir()):
        raise FileExistsError(f"{out} exists and is not empty; choose a new --out")
    patches_per_side = dims["image_size"] // dims["patch_size"]
    image_seq_len = (patches_per_side // SCALE_FACTOR) ** 2

    tokenizer = _train_tokenizer(dims["vocab_size"], tasks)
    image_size = {"longest_edge": dims["image_size"]}
    image_processor = SmolVLMImageProcessor(
        size=image_size, max_image_size=image_size, do_image_splitting=False
    )
    video_processor = SmolVLMVideoProcessor(size=image_size, max_image_size=image_size)
    processor = SmolVLMProcessor(
        image_processor=image_processor,
        tokenizer=tokenizer,
        video_processor=video_processor,
        image_seq_len=image_seq_len,
    )
    text_config = {
        "model_type": "llama",
        "vocab_size": len(tokenizer),
        "hidden_size": dims["text_hidden"],
        "intermediate_size": 4 * dims["text_hidden"],
        "num_hidden_layers": dims["text_layers"],
        "num_attention_heads": dims["text_heads"],
        "num_key_value_heads": dims["text_kv_heads"],
        "max_position_embeddings": 2048,
        "pad_token_id": tokenizer.pad_token_id,
        "bos_token_id": tokenizer.bos_token_id,
        "eos_token_id": tokenizer.eos_token_id,
    }
    vision_config = {
        "hidden_size": dims["vision_hidden"],
        "intermediate_size": 4 * dims["vision_hidden"],
        "num_hidden_layers": dims["vision_layers"],
        "num_attention_heads": dims["vision_heads"],
        "image_size": dims["image_size"],
        "patch_size": dims["patch_size"],
    }
    config = SmolVLMConfig(
        text_config=text_config,
        vision_config=vision_config,
        scale_factor=SCALE_FACTOR,
        image_token_id=tokenizer.convert_tokens_to_ids(IMAGE_TOKENS["image_token"]),
        pad_token_id=tokenizer.pad_token_id,
        vocab_size=len(tokenizer),
        tie_word_embeddings=False,
    )
    out.mkdir(parents=True, exist_ok=True)
    config.save_pretrained(out)
    processor.save_pretrained(out)
    tokenizer.save_pretrained(out)
    (out / "phantom_vlm.json").write_text(
        json.dumps({"size": size, "image_size": dims["image_size"], "weights": False, **dims}, indent=2)
        + "\n"
    )
    return out


@dataclass
class MakeVLMConfig:
    # Directory to create (must not exist or be empty).
    out: str = ""
    # 'tiny' (CPU tests) or 'small' (CPU demos).
    size: str = "tiny"
    # Extra task strings to train the tokenizer on, e.g. --tasks='[pick up the red cube]'.
    tasks: list[str] = field(default_factory=list)
    # Vision patch size in pixels instead of the size's 16 (8 gives 4x the image tokens per camera).
    patch_size: int | None = None


def main(args: Sequence[str] | None = None) -> None:
    # Returns None: console scripts pass main()'s return value to sys.exit.
    from lerobot_phantom import register

    register()  # the LeRobot registrations (attacks as image transforms, env and policy types)
    cfg = draccus.parse(MakeVLMConfig, args=args)
    if not cfg.out:
        raise ValueError(
            "--out is required: the directory to write the SmolVLM config, tokenizer and processor to"
        )
    path = make_vlm(cfg.out, cfg.size, cfg.tasks, cfg.patch_size)
    image_size = VLM_SIZES[cfg.size]["image_size"]
    print(
        f"wrote {path}; train with --policy.vlm_model_name={path} --policy.load_vlm_weights=false "
        f"--policy.resize_imgs_with_padding='[{image_size},{image_size}]'"
    )


if __name__ == "__main__":
    main()
