"""The env's observation/action interface, importable without mujoco (for configs and dataset writers)."""

CAMERAS = ("front", "wrist")
CONTROL_HZ = 10
STATE_DIM = 4  # TCP x, y, z (m) and finger opening (m)
ACTION_DIM = 4  # dx, dy, dz in [-1, 1] (x MAX_STEP_M metres per step) and grip (> 0 closes)
MAX_STEP_M = 0.04
# a close grasps an object whose centre is this close to the TCP in xy (and GRASP_Z_TOL in z)
GRASP_XY_TOL = 0.02
GRASP_Z_TOL = 0.02
OBS_TYPES = ("pixels_agent_pos", "pixels")
STATE_NAMES = ("tcp_x", "tcp_y", "tcp_z", "gripper_opening")
ACTION_NAMES = ("dx", "dy", "dz", "grip")
