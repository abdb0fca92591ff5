"""Local homing: return to the place where the goal panorama was taken."""

from __future__ import annotations

import math

import numpy as np

from homing_gym.paths import connected
from homing_gym.scenes.base import Scene, clearance
from homing_gym.tasks.base import Episode, sample_free_pose
from homing_gym.tasks.goal_reaching import (GoalReachingTask, RewardConfig,
                                            checked_success_radius)


class LocalHomingTask(GoalReachingTask):
    """Start within ``start_distance`` metres of a random collision-free home pose, both
    ``clearance_margin`` metres clear of walls and objects and joined by a path for a
    disc of that radius (:func:`homing_gym.paths.connected`); the only goal is home (see
    :class:`GoalReachingTask` for ``success_radius`` and ``success_on``)."""

    def __init__(self, start_distance: tuple[float, float] = (0.3, 1.5),
                 success_radius: float = 0.15, success_on: str = "stop",
                 reward: RewardConfig = RewardConfig(), clearance_margin: float = 0.22):
        super().__init__(success_radius, success_on, reward)
        self.set_start_distance(start_distance)
        self.clearance_margin = clearance_margin

    def set_start_distance(self, start_distance: tuple[float, float],
                           success_radius: float | None = None) -> None:
        """Draw the following episodes' starts ``start_distance`` = (min, max) metres from
        home, min at least the success radius; ``success_radius`` (metres, optional)
        replaces that radius at the same time (a curriculum that narrows it). A bad value
        raises ``ValueError`` and leaves both as they were."""
        radius = checked_success_radius(self.success_radius if success_radius is None
                                        else success_radius)
        lo, hi = (start_distance if np.ndim(start_distance) == 1 and len(start_distance) == 2
                  else (math.nan, math.nan))
        if not (math.isfinite(lo) and math.isfinite(hi) and 0 <= lo <= hi):
            raise ValueError(f"start_distance must be (min, max) metres with 0 <= min <= max, "
                             f"got {start_distance!r}")
        if lo < radius:
            raise ValueError(f"start_distance {start_distance!r} m must start at or beyond "
                             f"success_radius {radius!r} m: an episode must not begin at home")
        self.start_distance = (float(lo), float(hi))
        self.success_radius = float(radius)

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
        """A home (:func:`sample_free_pose`), then up to 20 starts at a uniform distance
        in ``start_distance`` and direction around it, until one is clear and joined to
        home; up to ``max_tries`` homes, then ``ValueError``."""
        margin = self.clearance_margin
        for _ in range(max_tries):
            home = sample_free_pose(scene, rng, margin)
            for _ in range(20):
                d = rng.uniform(*self.start_distance)
                a = rng.uniform(-np.pi, np.pi)
                xy = (home[0] + d * math.cos(a), home[1] + d * math.sin(a))
                if clearance(scene, xy) >= margin and connected(scene, home, xy, margin):
                    start = np.array([xy[0], xy[1], rng.uniform(-np.pi, np.pi)])
                    return Episode(home=home, start=start)
        raise ValueError(f"scene {scene.name!r} of size {scene.size} m holds no home and start "
                         f"{self.start_distance[0]}-{self.start_distance[1]} m apart with "
                         f"{margin} m of clearance that a disc of {margin} m radius can travel "
                         f"between (tried {max_tries} homes); use a smaller start_distance "
                         f"or a more open scene")
