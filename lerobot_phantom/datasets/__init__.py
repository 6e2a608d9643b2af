"""Attack-augmented datasets: the online mixer (``PhantomDataset``) and the offline ``lerobot-phantom-augment``."""

from lerobot_phantom.datasets.mixer import LABEL_KEYS, PhantomDataset, camera_attack_params

__all__ = ["LABEL_KEYS", "PhantomDataset", "camera_attack_params"]
