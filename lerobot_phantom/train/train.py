"""``lerobot-phantom-train``: every ``lerobot-train`` flag plus the ``--phantom.*`` group, on LeRobot's own loop.

``lerobot-train --policy.type=pi0 ...`` becomes ``lerobot-phantom-train --policy.type=pi0 ... --phantom.rate=0.3``.
The config is LeRobot's ``TrainPipelineConfig`` with one more field, ``phantom`` (``PhantomConfig``), so it is saved
in each checkpoint's ``train_config.json`` and restored by ``--resume=true --config_path=.../train_config.json``.

The training loop is LeRobot's ``train()`` itself (pinned to lerobot 0.4.4). For the duration of the call, five
names it looks up in its module are swapped (see ``_lerobot_compat.patched_train_loop``):

* ``make_dataset``: the dataset LeRobot builds is wrapped in ``PhantomDataset`` (rank/world size from accelerate;
  which samples are attacked depends only on (seed, epoch, index), so every process agrees);
* ``cycle``: sets the mixer's epoch each time the dataloader starts a new pass (continuing after ``--resume``);
* ``make_pre_post_processors``: the preprocessor is wrapped in ``TrainingPreprocessor`` - labels kept for logging,
  and with ``--phantom.where=device`` the attack step in front; the saved preprocessor stays the clean one;
* ``make_policy``: guard for LeRobot bug #3459 (resuming a PEFT run re-wraps the loaded adapter with a fresh one);
* ``update_policy``: per-attack training loss (see ``loss_log.py``).

PEFT/LoRA is LeRobot's own ``--peft.*``. LeRobot refuses PEFT without a pretrained policy, hence the two-stage
recipe: train clean, then ``--policy.path=<clean>/checkpoints/last/pretrained_model --peft.r=8 --phantom.rate=0.3``.
"""

# No `from __future__ import annotations`: LeRobot's parser.wrap reads the config class from the annotation.
import logging
import os
import sys
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Any

from lerobot_phantom import _lerobot_compat as compat
from lerobot_phantom.config import PhantomConfig

TrainPipelineConfig = compat.train_pipeline_config_class()


@dataclass
class PhantomTrainPipelineConfig(TrainPipelineConfig):
    # The attack mix used during training (the --phantom.* group); see lerobot_phantom.config.PhantomConfig.
    phantom: PhantomConfig = field(default_factory=PhantomConfig)
    # Entries of observation.state the policy never sees (e.g. [3], phantom_table's gripper opening); the mask is
    # saved in the checkpoint's preprocessor, so evaluation applies it too. See lerobot_phantom.train.state_mask.
    mask_state: list[int] = field(default_factory=list)

    def validate(self) -> None:
        super().validate()
        self.phantom.validate()
        if any(not isinstance(i, int) or i < 0 for i in self.mask_state) or len(set(self.mask_state)) != len(
            self.mask_state
        ):
            raise ValueError(
                f"--mask_state takes distinct indices >= 0 of observation.state, e.g. '[3]'; got {self.mask_state}"
            )
        if self.dataset.streaming:
            raise ValueError(
                "--dataset.streaming=true is not supported by lerobot-phantom-train: the mixer plans exact attack "
                "fractions per epoch over indexed samples. Train from a local copy, or write attacked data offline "
                "with lerobot-phantom-augment and use plain lerobot-train."
            )


def _unwrap_policy(policy: Any) -> Any:
    """The ``PreTrainedPolicy`` inside DDP / PEFT wrappers."""
    inner = getattr(policy, "module", policy)
    get_base_model = getattr(inner, "get_base_model", None)
    return get_base_model() if callable(get_base_model) else inner


def guard_peft_resume(policy: Any, peft_requested: bool) -> Any:
    """Keep an adapter loaded by ``make_policy`` (LeRobot bug #3459) and make it trainable again.

    When the policy config says ``use_peft`` (a ``--resume`` of a PEFT run, or ``--policy.path`` pointing at an
    adapter checkpoint), ``make_policy`` returns a ``PeftModel`` with the trained adapter loaded in inference mode;
    ``train()`` then calls ``wrap_with_peft`` again, which adds a freshly initialised adapter and trains that. The
    guard turns that second ``wrap_with_peft`` into a no-op for this object and re-enables gradients on the loaded
    adapter, which is what a resumed run should train.
    """
    from peft import PeftModel

    if not (peft_requested and isinstance(policy, PeftModel)):
        return policy
    adapters = list(policy.active_adapters)
    policy.set_requires_grad(adapters, requires_grad=True)
    for name in adapters:
        policy.peft_config[name].inference_mode = False

    def keep_loaded_adapter(peft_config: Any = None, peft_cli_overrides: dict | None = None) -> Any:
        logging.info(
            "lerobot-phantom: policy already carries its PEFT adapter(s) %s; not re-wrapping", adapters
        )
        return policy

    # An instance attribute shadows the forwarded PreTrainedPolicy.wrap_with_peft for this object only.
    policy.wrap_with_peft = keep_loaded_adapter
    return policy


class _PhantomTrainingRun:
    """The hooks of one ``train_phantom`` call (they share the dataset, the start epoch and the loss log)."""

    def __init__(self, cfg: PhantomTrainPipelineConfig) -> None:
        self.cfg = cfg
        self.originals: dict[str, Any] = {}
        self.dataset: Any = None
        self.start_epoch = 0
        self.loss_log: Any = None

    # -- make_dataset -------------------------------------------------------------------------------------
    def make_dataset(self, cfg: Any) -> Any:
        from lerobot_phantom.datasets import PhantomDataset

        base = self.originals["make_dataset"](cfg)
        state = compat.accelerate_process_state()
        self.dataset = PhantomDataset(
            base,
            cfg.phantom,
            apply=cfg.phantom.where == "dataloader",
            rank=state.process_index,
            world_size=state.num_processes,
        )
        if cfg.resume and cfg.checkpoint_path is not None:
            # LeRobot restarts the dataloader on resume; continue the epoch count rather than replay epoch 0.
            samples_seen = (
                compat.load_checkpoint_step(cfg.checkpoint_path) * cfg.batch_size * state.num_processes
            )
            self.start_epoch = samples_seen // max(1, len(self.dataset))
        self.dataset.set_epoch(self.start_epoch)
        return self.dataset

    # -- cycle ----------------------------------------------------------------------------------------------
    def cycle(self, dataloader: Any) -> Iterator[Any]:
        epoch = self.start_epoch
        while True:
            # accelerate's DataLoaderShard.set_epoch also forwards to the dataset in most set-ups; set both anyway.
            if hasattr(dataloader, "set_epoch"):
                dataloader.set_epoch(epoch)
            self.dataset.set_epoch(epoch)
            yield from dataloader
            epoch += 1

    # -- make_pre_post_processors -----------------------------------------------------------------------
    def make_pre_post_processors(self, *args: Any, **kwargs: Any) -> tuple[Any, Any]:
        from lerobot_phantom.train.device_step import PhantomAttackProcessorStep, TrainingPreprocessor
        from lerobot_phantom.train.state_mask import add_state_mask

        preprocessor, postprocessor = self.originals["make_pre_post_processors"](*args, **kwargs)
        preprocessor = add_state_mask(preprocessor, self.cfg.mask_state)
        attack_step = None
        if self.cfg.phantom.where == "device":
            attack_step = PhantomAttackProcessorStep(
                phantom=self.cfg.phantom,
                camera_keys=list(self.dataset.camera_keys),
                device=str(compat.accelerate_process_state().device),
            )
        return TrainingPreprocessor(preprocessor, attack_step), postprocessor

    # -- make_policy --------------------------------------------------------------------------------------
    def make_policy(self, *args: Any, **kwargs: Any) -> Any:
        policy = self.originals["make_policy"](*args, **kwargs)
        return guard_peft_resume(policy, peft_requested=self.cfg.peft is not None)

    # -- update_policy ------------------------------------------------------------------------------------
    def update_policy(
        self, train_metrics: Any, policy: Any, batch: dict[str, Any], *args: Any, **kwargs: Any
    ):
        from lerobot_phantom.train.loss_log import PerAttackLossLog

        accelerator = kwargs["accelerator"]
        if self.loss_log is None:
            self.loss_log = PerAttackLossLog(
                _unwrap_policy(accelerator.unwrap_model(policy)),
                accelerator=accelerator,
                log_freq=self.cfg.log_freq,
                output_dir=self.cfg.output_dir,
                final_step=self.cfg.steps,
            )
        labels, batch = self.loss_log.split_labels(batch)
        train_metrics, output_dict = self.originals["update_policy"](
            train_metrics, policy, batch, *args, **kwargs
        )
        output_dict = dict(output_dict or {})
        output_dict.update(self.loss_log.after_update(labels, batch, step=train_metrics.steps + 1))
        return train_metrics, output_dict

    def close(self) -> None:
        if self.loss_log is not None:
            self.loss_log.close()


def train_phantom(cfg: PhantomTrainPipelineConfig) -> None:
    """Run LeRobot's training loop with the phantom hooks (see the module docstring).

    ``cfg`` is validated by LeRobot's ``train()``. LeRobot resolves ``--policy.path`` and ``--config_path`` (resume)
    from ``sys.argv`` during validation; ``main(args)`` sets that up, so call ``main`` for those two cases.
    """
    if not isinstance(cfg, PhantomTrainPipelineConfig):
        raise TypeError(f"train_phantom needs a PhantomTrainPipelineConfig, got {type(cfg).__name__}")
    run = _PhantomTrainingRun(cfg)
    hooks = {name: getattr(run, name) for name in compat.TRAIN_LOOP_HOOKS}
    try:
        with compat.patched_train_loop(**hooks) as originals:
            run.originals = originals
            compat.train_loop_function()(cfg)
    finally:
        run.close()


@contextmanager
def _argv(args: Sequence[str] | None) -> Iterator[None]:
    """LeRobot's config parser (and ``TrainPipelineConfig.validate``) read ``sys.argv`` directly."""
    if args is None:
        yield
        return
    saved = sys.argv
    sys.argv = [saved[0] if saved else "lerobot-phantom-train", *args]
    try:
        yield
    finally:
        sys.argv = saved


def _run_from_cli(cfg: PhantomTrainPipelineConfig) -> None:
    train_phantom(cfg)


# At most this many cores: one torch thread per process (see default_torch_threads).
FEW_CORES = 2


def default_torch_threads() -> int | None:
    """One torch thread on a machine with at most ``FEW_CORES`` cores, unless ``OMP_NUM_THREADS`` says otherwise.

    On two shared cores torch's default (one thread per core) made a SmolVLA update about four times slower than one
    thread whenever anything else ran (issue 11; ``scripts/bench_train.py --threads``). Returns the count set, or
    None when torch's own default is kept.
    """
    if "OMP_NUM_THREADS" in os.environ or (os.cpu_count() or 1) > FEW_CORES:
        return None
    import torch

    torch.set_num_threads(1)
    return 1


def main(args: Sequence[str] | None = None) -> None:
    """``lerobot-phantom-train [lerobot-train flags] [--phantom.* flags]``; ``args`` defaults to ``sys.argv[1:]``."""
    from lerobot_phantom import register

    register()  # the LeRobot registrations (attacks as image transforms, env and policy types)
    default_torch_threads()
    compat.register_lerobot_plugins()
    # Importing LeRobot's training script registers every policy/env/optimizer config type for draccus.
    compat.train_script_module()
    with _argv(args):
        compat.config_parser_wrap()()(_run_from_cli)()


if __name__ == "__main__":
    main()
