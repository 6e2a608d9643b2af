"""Per-attack training loss, from the mixer's labels, next to LeRobot's usual training logs.

Two ways, chosen per policy, both cheap and both stated in the log:

* ``per_sample`` - when the policy's ``forward`` takes ``reduction`` (SmolVLA, pi0, ...): the training forward itself
  is asked for per-sample losses (``reduction="none"``) and their mean is returned to LeRobot's ``update_policy``,
  which is the same batch-mean loss it would have computed (every sample has the same number of loss terms). So
  the per-attack loss is that of the very forward pass being trained on, every step, at no extra cost; it is
  averaged over the ``log_freq`` window.
* ``log_step_forward`` - otherwise (ACT's ``forward`` only returns a batch mean): at log steps only, one extra
  no-grad forward per attack group of the current batch, in training mode, inside ``torch.random.fork_rng`` so
  logging does not change the training run's random stream. Noisier (one batch), but costs nothing between logs.

Logged at LeRobot's log steps and at the last step: a ``phantom:`` line in the log, ``phantom/loss/<attack>`` (plus
``phantom/attacked_fraction``) in the dict LeRobot sends to wandb, and one JSON line per log step in
``<output_dir>/phantom_train_log.jsonl``. Group names: ``clean`` (neither channel attacked), the camera/main attack's
name, and ``instruction:<name>`` for the instruction channel. ``seen`` counts every sample the loop trained on
(all processes), so the attacked fraction the loop actually saw can be checked against ``--phantom.rate``.
"""

from __future__ import annotations

import inspect
import json
import logging
from pathlib import Path
from typing import Any

import torch

from lerobot_phantom.datasets import LABEL_KEYS
from lerobot_phantom.transforms.registry import ATTACK_NAMES, CLEAN_ID

LOG_FILE_NAME = "phantom_train_log.jsonl"
CLEAN = "clean"
INSTRUCTION_PREFIX = "instruction:"
# Group slots: 0 = clean, 1 + id = main-channel attack id, 1 + len + id = instruction-channel attack id.
_NUM_SLOTS = 1 + 2 * len(ATTACK_NAMES)


def group_names() -> list[str]:
    return [CLEAN, *ATTACK_NAMES, *(INSTRUCTION_PREFIX + name for name in ATTACK_NAMES)]


def group_membership(labels: dict[str, torch.Tensor]) -> torch.Tensor:
    """(B, slots) bool: which loss groups each sample belongs to (a sample can be in a main and an instruction group)."""
    attack = labels["phantom.attack"].reshape(-1).cpu()
    instruction = labels["phantom.instruction_attack"].reshape(-1).cpu()
    member = torch.zeros(attack.numel(), _NUM_SLOTS, dtype=torch.bool)
    rows = torch.arange(attack.numel())
    member[rows, 0] = (attack == CLEAN_ID) & (instruction == CLEAN_ID)
    has_main = attack != CLEAN_ID
    member[rows[has_main], 1 + attack[has_main]] = True
    has_instruction = instruction != CLEAN_ID
    member[rows[has_instruction], 1 + len(ATTACK_NAMES) + instruction[has_instruction]] = True
    return member


def _select(batch: dict[str, Any], rows: torch.Tensor, batch_size: int) -> dict[str, Any]:
    out = {}
    for key, value in batch.items():
        if isinstance(value, torch.Tensor) and value.ndim > 0 and value.shape[0] == batch_size:
            out[key] = value[rows.to(value.device)]
        elif isinstance(value, list) and len(value) == batch_size:
            out[key] = [value[i] for i in rows.tolist()]
        else:
            out[key] = value
    return out


def _own_gloo_group(accelerator: Any):
    """A gloo process group for the log's sums alone (None in one process); every rank builds it at the same step.

    Not accelerate's ``reduce`` on LeRobot's group: a collective there hands that group's worker thread a tensor made
    in Python, and the barriers LeRobot queues at the end of training keep the finished work alive. Torch 2.10
    releases a tensor's Python object (which takes the GIL) whenever the C++ side drops its second-last reference,
    even if Python still holds the tensor. At the end of training the main thread holds the GIL while it joins that
    worker (destroying DDP's process group), and the worker waits for the GIL to free the work: a deadlock after
    "End of training" (docs/bench/ddp_teardown.md). A group of its own has no barriers: its worker frees each
    reduction as soon as it is done, while the main thread still runs Python code and gives the GIL up."""
    if accelerator.num_processes <= 1 or not torch.distributed.is_initialized():
        return None
    return torch.distributed.new_group(backend="gloo")


class PerAttackLossLog:
    """Collects per-group losses during training; see the module docstring."""

    def __init__(
        self,
        policy: Any,
        *,
        accelerator: Any,
        log_freq: int,
        output_dir: str | Path | None,
        final_step: int | None = None,
    ) -> None:
        self.policy = policy
        self.accelerator = accelerator
        self.log_freq = int(log_freq)
        self.final_step = final_step
        self.path = Path(output_dir) / LOG_FILE_NAME if output_dir is not None else None
        forward_parameters = inspect.signature(policy.forward).parameters
        self.mode = "per_sample" if "reduction" in forward_parameters else "log_step_forward"
        self._last_per_sample: torch.Tensor | None = None
        self._original_forward = None
        if self.mode == "per_sample":
            self._install_per_sample_forward()
        self._window_sum = torch.zeros(_NUM_SLOTS, dtype=torch.float64)
        self._window_count = torch.zeros(_NUM_SLOTS, dtype=torch.float64)
        self._seen = torch.zeros(_NUM_SLOTS, dtype=torch.float64)
        self._seen_total = torch.zeros((), dtype=torch.float64)
        self._group = _own_gloo_group(accelerator)
        logging.info("lerobot-phantom: per-attack loss logging in %r mode", self.mode)

    # -- per-sample forward ---------------------------------------------------------------------------------
    def _install_per_sample_forward(self) -> None:
        original = self.policy.forward
        self._original_forward = original

        def forward(batch: dict[str, Any], *args: Any, reduction: str = "mean", **kwargs: Any):
            if reduction != "mean":
                return original(batch, *args, reduction=reduction, **kwargs)
            per_sample, output = original(batch, *args, reduction="none", **kwargs)
            self._last_per_sample = per_sample.detach()
            return per_sample.mean(), output

        # Instance attribute: nn.Module.__call__ (and PEFT / DDP, which call the module) pick it up.
        self.policy.forward = forward

    def close(self) -> None:
        # Called after LeRobot's loop returned; its end_training destroyed every process group, this log's too.
        self._group = None
        if self._original_forward is not None:
            del self.policy.forward
            self._original_forward = None

    # -- per step -------------------------------------------------------------------------------------------
    @staticmethod
    def split_labels(batch: dict[str, Any]) -> tuple[dict[str, Any] | None, dict[str, Any]]:
        """(labels, the batch without them); labels is None for a batch the mixer did not label."""
        if "phantom.attack" not in batch:
            return None, batch
        labels = {key: batch[key] for key in LABEL_KEYS if key in batch}
        return labels, {key: value for key, value in batch.items() if key not in labels}

    def after_update(
        self, labels: dict[str, Any] | None, batch: dict[str, Any], step: int
    ) -> dict[str, float]:
        if labels is None:
            return {}
        member = group_membership(labels)
        self._seen += member.sum(0).to(torch.float64)
        self._seen_total += member.shape[0]
        if self.mode == "per_sample" and self._last_per_sample is not None:
            losses = self._last_per_sample.reshape(-1).to("cpu", torch.float64)
            self._window_sum += (member.to(torch.float64) * losses[:, None]).sum(0)
            self._window_count += member.sum(0).to(torch.float64)
            self._last_per_sample = None
        is_log_step = self.log_freq > 0 and step % self.log_freq == 0
        if not (is_log_step or step == self.final_step):
            return {}
        if self.mode == "log_step_forward":
            self._window_sum.zero_()
            self._window_count.zero_()
            self._forward_per_group(member, batch)
        return self._flush(step)

    def _forward_per_group(self, member: torch.Tensor, batch: dict[str, Any]) -> None:
        batch_size = member.shape[0]
        devices = [torch.cuda.current_device()] if torch.cuda.is_available() else []
        with torch.no_grad(), torch.random.fork_rng(devices=devices), self.accelerator.autocast():
            for slot in torch.nonzero(member.any(0)).reshape(-1).tolist():
                rows = torch.nonzero(member[:, slot]).reshape(-1)
                loss, _ = self.policy.forward(_select(batch, rows, batch_size))
                self._window_sum[slot] += float(loss) * rows.numel()
                self._window_count[slot] += rows.numel()

    def _flush(self, step: int) -> dict[str, float]:
        # Every process reaches its log steps together (same step counter), so the reduction is collective.
        stacked = torch.stack([self._window_sum, self._window_count, self._seen])
        stacked = torch.cat([stacked.reshape(-1), self._seen_total.reshape(1)])
        if self._group is not None:
            torch.distributed.all_reduce(stacked, op=torch.distributed.ReduceOp.SUM, group=self._group)
        window_sum, window_count, seen = stacked[:-1].reshape(3, _NUM_SLOTS)
        seen_total = float(stacked[-1])
        self._window_sum.zero_()
        self._window_count.zero_()

        names = group_names()
        losses = {
            names[j]: float(window_sum[j] / window_count[j]) for j in range(_NUM_SLOTS) if window_count[j] > 0
        }
        counts = {names[j]: int(window_count[j]) for j in range(_NUM_SLOTS) if window_count[j] > 0}
        seen_counts = {names[j]: int(seen[j]) for j in range(_NUM_SLOTS) if seen[j] > 0}
        attacked = seen_total - seen_counts.get(CLEAN, 0)
        record = {
            "step": step,
            "mode": self.mode,
            "loss": losses,
            "loss_samples": counts,
            "seen": {"total": int(seen_total), "attacked": int(attacked), "groups": seen_counts},
        }
        if self.accelerator.is_main_process:
            shown = " ".join(f"{name}:{loss:.3f}(n={counts[name]})" for name, loss in losses.items())
            logging.info(
                "phantom step:%d attacked_seen:%d/%d loss[%s] %s",
                step,
                int(attacked),
                int(seen_total),
                self.mode,
                shown,
            )
            if self.path is not None:
                self.path.parent.mkdir(parents=True, exist_ok=True)
                with self.path.open("a") as f:
                    f.write(json.dumps(record) + "\n")
        out = {f"phantom/loss/{name}": value for name, value in losses.items()}
        out["phantom/attacked_fraction"] = attacked / seen_total if seen_total else 0.0
        return out
