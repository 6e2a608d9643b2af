"""The hooks lerobot-phantom-train puts into LeRobot's loop: epoch counter, resume epoch, PEFT resume guard."""

import pytest
import torch

from lerobot_phantom.config import PhantomConfig
from lerobot_phantom.train.train import PhantomTrainPipelineConfig, _PhantomTrainingRun, guard_peft_resume


class _Labelled(torch.utils.data.Dataset):
    """Stand-in for the mixer: records the epoch each sample was read in."""

    def __init__(self, n: int) -> None:
        self.n = n
        self.epoch = -1

    def set_epoch(self, epoch: int) -> None:
        self.epoch = epoch

    def __len__(self) -> int:
        return self.n

    def __getitem__(self, index: int) -> dict:
        return {"index": index, "epoch": self.epoch}


def test_cycle_advances_the_mixer_epoch_on_every_pass():
    from accelerate import Accelerator

    run = _PhantomTrainingRun(cfg=None)
    run.dataset = _Labelled(6)
    run.start_epoch = 2
    loader = Accelerator(cpu=True).prepare(
        torch.utils.data.DataLoader(run.dataset, batch_size=4, shuffle=True)
    )
    batches = run.cycle(loader)
    epochs = [next(batches)["epoch"].tolist() for _ in range(6)]  # 2 batches per pass, 3 passes
    assert epochs == [[2] * 4, [2] * 2, [3] * 4, [3] * 2, [4] * 4, [4] * 2]


def test_resume_continues_the_epoch_count(tmp_path, tiny_dataset_root, monkeypatch):
    from lerobot.configs.default import DatasetConfig
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    from lerobot_phantom import _lerobot_compat as compat

    cfg = PhantomTrainPipelineConfig(
        dataset=DatasetConfig(repo_id="phantom/tiny", root=str(tiny_dataset_root)),
        resume=True,
        batch_size=4,
        phantom=PhantomConfig(rate=0.3),
    )
    cfg.checkpoint_path = tmp_path
    run = _PhantomTrainingRun(cfg)
    run.originals = {"make_dataset": lambda c: LeRobotDataset(c.dataset.repo_id, root=c.dataset.root)}
    monkeypatch.setattr(compat, "load_checkpoint_step", lambda path: 13)  # 13 steps x 4 samples of 24 frames
    dataset = run.make_dataset(cfg)
    assert run.start_epoch == 2 and dataset.epoch == 2
    assert dataset.world_size == compat.accelerate_process_state().num_processes


def test_peft_guard_keeps_a_loaded_adapter_trainable_and_refuses_to_rewrap():
    from peft import LoraConfig, PeftModel, get_peft_model

    base = torch.nn.Sequential(torch.nn.Linear(4, 4), torch.nn.ReLU(), torch.nn.Linear(4, 2))
    trained = get_peft_model(base, LoraConfig(r=2, target_modules=["0", "2"], init_lora_weights=False))
    state = {k: v.clone() for k, v in trained.state_dict().items() if "lora_" in k}
    # As make_policy loads it: PeftModel.from_pretrained(..., is_trainable=False) -> adapters frozen.
    trained.set_requires_grad(["default"], requires_grad=False)
    trained.peft_config["default"].inference_mode = True

    guarded = guard_peft_resume(trained, peft_requested=True)
    assert isinstance(guarded, PeftModel)
    assert guarded.wrap_with_peft(peft_cli_overrides={"r": 8}) is guarded
    lora = {k: p for k, p in guarded.named_parameters() if "lora_" in k}
    assert lora and all(p.requires_grad for p in lora.values())
    assert all(torch.equal(guarded.state_dict()[k], v) for k, v in state.items())
    assert guarded.peft_config["default"].inference_mode is False
    # A plain policy, or no --peft.*, is left alone.
    plain = torch.nn.Linear(2, 2)
    assert guard_peft_resume(plain, peft_requested=True) is plain and not hasattr(plain, "wrap_with_peft")


def test_streaming_datasets_are_refused_with_a_reason(tmp_path):
    import draccus

    from lerobot_phantom import _lerobot_compat as compat

    compat.train_script_module()
    cfg = draccus.parse(
        PhantomTrainPipelineConfig,
        args=[
            "--dataset.repo_id=x",
            "--dataset.streaming=true",
            "--policy.type=act",
            "--policy.push_to_hub=false",
            f"--output_dir={tmp_path / 'o'}",
        ],
    )
    with pytest.raises(ValueError, match=r"--dataset\.streaming.*lerobot-phantom-augment"):
        cfg.validate()
