"""Tasks: episode logic (starts, rewards, ends) plugged into the env core."""

from homing_gym.tasks.base import Episode, Task, sample_free_pose
from homing_gym.tasks.local_homing import SUCCESS_MODES, LocalHomingTask, RewardConfig

__all__ = ["SUCCESS_MODES", "Episode", "LocalHomingTask", "RewardConfig", "Task",
           "sample_free_pose"]
