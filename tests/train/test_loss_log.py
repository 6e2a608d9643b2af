"""PerAttackLossLog on its own, in one process (the end-to-end runs are in test_train.py)."""

import contextlib

import torch

from lerobot_phantom.train.loss_log import CLEAN, PerAttackLossLog
from lerobot_phantom.transforms.registry import ATTACK_NAMES, CLEAN_ID


class BatchMeanPolicy(torch.nn.Module):
    """A policy whose ``forward`` has no ``reduction`` argument, like ACT's."""

    def forward(self, batch):
        return batch["observation.state"].mean(), {}


class LeRobotAccelerator:
    """What the log uses of the Accelerator LeRobot's loop made; a collective on LeRobot's process group fails."""

    is_main_process = True

    def __init__(self, num_processes: int = 1) -> None:
        self.num_processes = num_processes

    def autocast(self):
        return contextlib.nullcontext()

    def reduce(self, tensor, reduction="mean"):
        raise AssertionError("the log reduced on LeRobot's process group")


def labelled_batch() -> tuple[dict, dict]:
    attack = torch.tensor([CLEAN_ID, 0, CLEAN_ID, 1])
    labels = {"phantom.attack": attack, "phantom.instruction_attack": torch.full_like(attack, CLEAN_ID)}
    batch = {"observation.state": torch.arange(8.0).reshape(4, 2)}
    return labels, batch


def test_a_log_step_logs_the_mean_loss_of_each_group():
    log = PerAttackLossLog(BatchMeanPolicy(), accelerator=LeRobotAccelerator(), log_freq=1, output_dir=None)
    labels, batch = labelled_batch()
    logged = log.after_update(labels, batch, step=1)
    assert logged[f"phantom/loss/{CLEAN}"] == (0 + 1 + 4 + 5) / 4  # rows 0 and 2
    assert logged[f"phantom/loss/{ATTACK_NAMES[0]}"] == (2 + 3) / 2
    assert logged[f"phantom/loss/{ATTACK_NAMES[1]}"] == (6 + 7) / 2
    assert logged["phantom/attacked_fraction"] == 0.5


def test_several_processes_sum_the_log_over_a_gloo_group_of_its_own(tmp_path):
    """Not on LeRobot's process group: torch 2.10 frees a reduced tensor's Python object on the group's worker
    thread whenever LeRobot's closing barriers let go of the work, and LeRobot joins that thread holding the GIL (a
    deadlock, docs/bench/ddp_teardown.md). One real process here, in a world of one."""
    torch.distributed.init_process_group(
        "gloo", init_method=f"file://{tmp_path / 'store'}", rank=0, world_size=1
    )
    try:
        log = PerAttackLossLog(
            BatchMeanPolicy(), accelerator=LeRobotAccelerator(num_processes=2), log_freq=1, output_dir=None
        )
        assert log._group is not None and log._group is not torch.distributed.group.WORLD
        labels, batch = labelled_batch()
        logged = log.after_update(labels, batch, step=1)
        assert logged[f"phantom/loss/{CLEAN}"] == (0 + 1 + 4 + 5) / 4
        assert logged["phantom/attacked_fraction"] == 0.5
        log.close()
    finally:
        torch.distributed.destroy_process_group()
