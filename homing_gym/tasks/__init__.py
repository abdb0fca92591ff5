"""Tasks: episode logic (starts, goals, rewards, ends) plugged into the env core."""

from homing_gym.tasks.base import Episode, Task, sample_free_pose
from homing_gym.tasks.goal_reaching import SUCCESS_MODES, GoalReachingTask, RewardConfig
from homing_gym.tasks.local_homing import LocalHomingTask

__all__ = ["SUCCESS_MODES", "Episode", "GoalReachingTask", "LocalHomingTask", "RewardConfig",
           "Task", "sample_free_pose"]
