"""lerobot-phantom: physical sensor attacks for LeRobot policies (Phantom Menace, AAAI-26)."""

__version__ = "0.1.0"
