"""Does a checkpoint decide the gripper from the image or copy it from the proprioceptive state?

In the scripted demonstrations the gripper action equals the current gripper state on every frame but the two
transitions of an episode (close at the grasp, open at the release): copying the state scores ~93 % on that
dimension and never grasps. This probe feeds each checkpoint the dataset's transition frames (state open, label
close; state closed, label open) and reports how often the first action of the predicted chunk makes the
transition, then repeats it with only the gripper entry of the state replaced by the other value
(counterfactual): a policy that reads the scene keeps its decision, a copying one follows the state.

    python scripts/recipe_gripper_probe.py CKPT_DIR [CKPT_DIR ...] --dataset-root DIR --out FILE.json

Flow-matching noise comes from a seeded ``torch.Generator`` (the same draws for every checkpoint and variant).
"""

from __future__ import annotations

import argparse
import json
import os
from pathlib import Path

os.environ.setdefault("HF_HUB_OFFLINE", "1")

import torch

GRIP = 3  # index of the gripper in observation.state (gripper_opening) and in the action (grip > 0 closes)


def transition_frames(dataset) -> tuple[list[int], list[int], float, float]:
    """Indices where the gripper action changes the gripper state (closing, opening) and the closed and open values."""
    states = torch.stack([torch.as_tensor(s) for s in dataset.hf_dataset["observation.state"]])
    actions = torch.stack([torch.as_tensor(a) for a in dataset.hf_dataset["action"]])
    closed_state = states[:, GRIP] < states[:, GRIP].max() - 1e-3
    closes = actions[:, GRIP] > 0
    closing = torch.nonzero(~closed_state & closes).flatten().tolist()
    opening = torch.nonzero(closed_state & ~closes).flatten().tolist()
    return closing, opening, states[:, GRIP].min().item(), states[:, GRIP].max().item()


def predict_first_grip(policy, preprocessor, postprocessor, frames: list[dict], seed: int) -> torch.Tensor:
    from torch.utils.data import default_collate

    batch = default_collate(frames)
    batch = {k: v for k, v in batch.items() if k.startswith("observation.") or k == "task"}
    batch = preprocessor(batch)
    cfg = policy.config
    generator = torch.Generator().manual_seed(seed)
    noise = torch.randn((len(frames), cfg.chunk_size, cfg.max_action_dim), generator=generator)
    chunk = policy.predict_action_chunk(batch, noise=noise)
    return postprocessor(chunk[:, 0])[:, GRIP]


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("checkpoints", nargs="+", type=Path)
    parser.add_argument("--dataset-root", type=Path, required=True)
    parser.add_argument("--repo-id", default="local/phantom_goal")
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--batch", type=int, default=25)
    args = parser.parse_args()
    if args.out.exists():
        raise FileExistsError(f"{args.out} exists; choose another --out")

    from lerobot.datasets.lerobot_dataset import LeRobotDataset
    from recipe_rollouts import load

    dataset = LeRobotDataset(args.repo_id, root=args.dataset_root)
    closing, opening, closed_value, open_value = transition_frames(dataset)
    results = []
    for checkpoint in args.checkpoints:
        policy, preprocessor, postprocessor = load(checkpoint)
        row = {"checkpoint": str(checkpoint)}
        for name, indices, flipped_value, wants_close in (
            ("closing", closing, closed_value, True),
            ("opening", opening, open_value, False),
        ):
            made, made_flipped = 0, 0
            for start in range(0, len(indices), args.batch):
                frames = [dataset[i] for i in indices[start : start + args.batch]]
                with torch.no_grad():
                    grip = predict_first_grip(policy, preprocessor, postprocessor, frames, args.seed + start)
                    for frame in frames:
                        frame["observation.state"] = frame["observation.state"].clone()
                        frame["observation.state"][GRIP] = flipped_value
                    grip_flipped = predict_first_grip(
                        policy, preprocessor, postprocessor, frames, args.seed + start
                    )
                made += int(((grip > 0) == wants_close).sum())
                made_flipped += int(((grip_flipped > 0) == wants_close).sum())
            row[name] = {
                "frames": len(indices),
                "transition_predicted": made,
                "transition_predicted_with_state_flipped": made_flipped,
            }
        print(json.dumps(row), flush=True)
        results.append(row)
    args.out.write_text(json.dumps(results, indent=2))


if __name__ == "__main__":
    main()
