"""PerAttackLossLog on its own, in one process (the end-to-end runs are in test_train.py)."""

import gc
import weakref

import torch

from lerobot_phantom.train.loss_log import CLEAN, PerAttackLossLog
from lerobot_phantom.transforms.registry import ATTACK_NAMES, CLEAN_ID


class BatchMeanPolicy(torch.nn.Module):
    """A policy whose ``forward`` has no ``reduction`` argument, like ACT's."""

    def forward(self, batch):
        return batch["observation.state"].mean(), {}


class RecordingAccelerator:
    """accelerate's single-process Accelerator, remembering (weakly) every tensor ``reduce`` returned."""

    def __init__(self) -> None:
        from accelerate import Accelerator

        self.inner = Accelerator(cpu=True)
        self.reduced: list[weakref.ref] = []

    def reduce(self, tensor, reduction="mean"):
        out = self.inner.reduce(tensor, reduction=reduction)
        self.reduced.append(weakref.ref(out))
        return out

    def __getattr__(self, name):
        return getattr(self.inner, name)


def labelled_batch() -> tuple[dict, dict]:
    attack = torch.tensor([CLEAN_ID, 0, CLEAN_ID, 1])
    labels = {"phantom.attack": attack, "phantom.instruction_attack": torch.full_like(attack, CLEAN_ID)}
    batch = {"observation.state": torch.arange(8.0).reshape(4, 2)}
    return labels, batch


def test_a_log_step_logs_the_mean_loss_of_each_group():
    accelerator = RecordingAccelerator()
    log = PerAttackLossLog(BatchMeanPolicy(), accelerator=accelerator, log_freq=1, output_dir=None)
    labels, batch = labelled_batch()
    logged = log.after_update(labels, batch, step=1)
    assert logged[f"phantom/loss/{CLEAN}"] == (0 + 1 + 4 + 5) / 4  # rows 0 and 2
    assert logged[f"phantom/loss/{ATTACK_NAMES[0]}"] == (2 + 3) / 2
    assert logged[f"phantom/loss/{ATTACK_NAMES[1]}"] == (6 + 7) / 2
    assert logged["phantom/attacked_fraction"] == 0.5


def test_the_reduced_tensor_stays_referenced_until_the_log_is_closed():
    """With gloo, the collective's work may drop its reference to the reduced tensor on a worker thread after the call
    returned; if that were the last reference, it would need the GIL, which the main thread holds while it joins that
    thread at the end of training (a deadlock, docs/bench/ddp_teardown.md). The log keeps the last reference."""
    accelerator = RecordingAccelerator()
    log = PerAttackLossLog(BatchMeanPolicy(), accelerator=accelerator, log_freq=1, output_dir=None)
    labels, batch = labelled_batch()
    log.after_update(labels, batch, step=1)
    gc.collect()
    (reduced,) = accelerator.reduced
    assert reduced() is not None
    log.close()
    gc.collect()
    assert reduced() is None
