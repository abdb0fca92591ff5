"""Tasks: episode logic (starts, goals, rewards, ends) plugged into the env core."""

from homing_gym.tasks.base import Episode, Task, sample_free_pose
from homing_gym.tasks.goal_reaching import SUCCESS_MODES, GoalReachingTask, RewardConfig
from homing_gym.tasks.landmark_navigation import LandmarkNavigationTask
from homing_gym.tasks.local_homing import LocalHomingTask
from homing_gym.tasks.long_range import LongRangeHomingTask
from homing_gym.tasks.route_following import RouteFollowingTask
from homing_gym.tasks.work_locations import WorkLocationsTask

__all__ = ["SUCCESS_MODES", "Episode", "GoalReachingTask", "LandmarkNavigationTask",
           "LocalHomingTask",
           "LongRangeHomingTask", "RewardConfig",
           "RouteFollowingTask", "Task", "WorkLocationsTask", "sample_free_pose"]
