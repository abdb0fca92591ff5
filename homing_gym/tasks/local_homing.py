"""Local homing: return to the place where the goal panorama was taken."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from homing_gym.scenes.base import Scene, clearance
from homing_gym.tasks.base import Episode, Task, sample_free_pose

if TYPE_CHECKING:
    from homing_gym.env import HomingEnv

SUCCESS_MODES = ("reach", "stop")


@dataclass(frozen=True)
class RewardConfig:
    """Reward weights. ``progress`` multiplies the decrease of the distance to home (per
    metre: potential-based shaping with potential ``-distance``); ``success`` is paid once
    on success; ``collision`` is subtracted on every step with contact; ``time`` on every step."""

    progress: float = 1.0
    success: float = 10.0
    collision: float = 0.1
    time: float = 0.01


class LocalHomingTask(Task):
    """Start within ``start_distance`` metres of a random collision-free home pose.

    ``success_on="reach"`` ends the episode as soon as the robot centre is within
    ``success_radius`` metres of home. ``success_on="stop"`` ends it when the agent issues
    the stop action, and counts success only if it stopped within ``success_radius``:
    the accuracy protocol of the papers, where the method decides it has arrived.
    """

    def __init__(self, start_distance: tuple[float, float] = (0.3, 1.5),
                 success_radius: float = 0.15, success_on: str = "reach",
                 reward: RewardConfig = RewardConfig(), clearance_margin: float = 0.22):
        lo, hi = (start_distance if np.ndim(start_distance) == 1 and len(start_distance) == 2
                  else (math.nan, math.nan))
        if not (math.isfinite(lo) and math.isfinite(hi) and 0 <= lo <= hi):
            raise ValueError(f"start_distance must be (min, max) metres with 0 <= min <= max, "
                             f"got {start_distance!r}")
        if not (math.isfinite(success_radius) and success_radius > 0):
            raise ValueError(f"success_radius must be a positive number of metres, "
                             f"got {success_radius!r}")
        if success_on not in SUCCESS_MODES:
            raise ValueError(f"unknown success_on {success_on!r}; allowed: {SUCCESS_MODES}")
        self.start_distance = (float(lo), float(hi))
        self.success_radius = float(success_radius)
        self.success_on = success_on
        self.reward = reward
        self.clearance_margin = clearance_margin
        self._prev_distance = 0.0

    def check_scene(self, scene: Scene) -> None:
        width, depth = scene.size
        reach = math.hypot(width, depth) - 2 * self.clearance_margin
        if self.start_distance[1] > reach:
            raise ValueError(
                f"start_distance {self.start_distance} m does not fit into scene "
                f"{scene.name!r} of size {width:.2f} x {depth:.2f} m: the maximum must be "
                f"at most {reach:.2f} m")

    def sample_episode(self, scene: Scene, rng: np.random.Generator,
                       max_tries: int = 200) -> Episode:
        for _ in range(max_tries):
            home = sample_free_pose(scene, rng, self.clearance_margin)
            for _ in range(20):
                d = rng.uniform(*self.start_distance)
                a = rng.uniform(-np.pi, np.pi)
                xy = (home[0] + d * math.cos(a), home[1] + d * math.sin(a))
                if clearance(scene, xy) >= self.clearance_margin:
                    start = np.array([xy[0], xy[1], rng.uniform(-np.pi, np.pi)])
                    return Episode(home=home, start=start)
        raise ValueError(f"start_distance {self.start_distance} m does not fit into scene "
                         f"{scene.name!r} of size {scene.size} m")

    def on_reset(self, env: "HomingEnv") -> None:
        self._prev_distance = env.distance_to_goal

    def step_outcome(self, env: "HomingEnv", collision: bool, stopped: bool):
        distance = env.distance_to_goal
        within = distance < self.success_radius
        if self.success_on == "stop":
            terminated = stopped
            success = stopped and within
        else:
            terminated = success = within
        rewards = {
            "progress": self.reward.progress * (self._prev_distance - distance),
            "success": self.reward.success if success else 0.0,
            "collision": -self.reward.collision if collision else 0.0,
            "time": -self.reward.time,
        }
        self._prev_distance = distance
        return rewards, terminated, success
