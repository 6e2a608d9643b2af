"""Constants and command-line builders shared by the train tests (a module of its own: `conftest` names collide)."""

from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
CONFIGS = REPO / "configs"
FRAMES = 24  # 2 episodes x 12 frames


def dataset_args(root: Path) -> list[str]:
    return ["--dataset.repo_id=phantom/tiny", f"--dataset.root={root}"]


def smolvla_args(root: Path, vlm: Path, out: Path, *extra: str) -> list[str]:
    """The tiny CPU config (configs/tiny_smolvla_cpu.json) pointed at the test's dataset, VLM and output dir."""
    return [
        f"--config_path={CONFIGS / 'tiny_smolvla_cpu.json'}",
        *dataset_args(root),
        f"--policy.vlm_model_name={vlm}",
        f"--output_dir={out}",
        *extra,
    ]
