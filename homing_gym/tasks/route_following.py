"""Route following: visit a sequence of target places, each known by its snapshot
(Hong et al. 1991 §5: 17 targets about 1 ft apart in a hallway, the robot starting 1 ft
before the first)."""

from __future__ import annotations

import math

import numpy as np

from homing_gym.geometry import FOOT, wrap_angle
from homing_gym.scenes.base import Scene, clearance
from homing_gym.tasks.context import TaskContext
from homing_gym.tasks.base import Episode
from homing_gym.tasks.goal_reaching import GoalReachingTask, RewardConfig
from homing_gym.validation import require_positive




class RouteFollowingTask(GoalReachingTask):
    """``n_targets`` target poses ``spacing`` metres apart on a straight line from the
    scene's ``metadata["route_origin"]`` (x, y, yaw), all facing along the route. The
    robot starts ``spacing`` metres before the first target, perturbed by up to
    ``start_jitter = (metres, radians)`` (uniform in x, y and yaw). A target counts as
    reached within ``success_radius`` (default 0.1 m, a third of the spacing), or, with
    ``success_on="stop"``, when the agent stops; then the next target's snapshot becomes
    the goal."""

    def __init__(self, n_targets: int = 17, spacing: float = FOOT,
                 start_jitter: tuple[float, float] = (0.05, math.radians(10)),
                 success_radius: float = 0.1, success_on: str = "reach",
                 reward: RewardConfig = RewardConfig(), clearance_margin: float = 0.18):
        if not (isinstance(n_targets, (int, np.integer)) and n_targets >= 1):
            raise ValueError(f"n_targets must be an integer >= 1, got {n_targets!r}")
        require_positive("spacing", spacing, "metres")
        if len(start_jitter) != 2 or not all(math.isfinite(v) and v >= 0 for v in start_jitter):
            raise ValueError(f"start_jitter must be (metres, radians) >= 0, got {start_jitter!r}")
        super().__init__(success_radius, success_on, reward)
        self.n_targets = int(n_targets)
        self.spacing = float(spacing)
        self.start_jitter = (float(start_jitter[0]), float(start_jitter[1]))
        self.clearance_margin = clearance_margin

    def _route(self, scene: Scene) -> list[np.ndarray]:
        x0, y0, yaw = scene.metadata["route_origin"]
        c, s = math.cos(yaw), math.sin(yaw)
        return [np.array([x0 + k * self.spacing * c, y0 + k * self.spacing * s, yaw])
                for k in range(-1, self.n_targets)]

    def check_scene(self, scene: Scene) -> None:
        if "route_origin" not in scene.metadata:
            raise ValueError(f"scene {scene.name!r} defines no route (metadata['route_origin']); "
                             f"use a scene with one, e.g. 'hallway'")
        for pose in self._route(scene):
            if clearance(scene, (pose[0], pose[1])) < self.clearance_margin:
                raise ValueError(
                    f"{self.n_targets} targets {self.spacing} m apart do not fit along the "
                    f"route of scene {scene.name!r}: ({pose[0]:.2f}, {pose[1]:.2f}) is blocked")

    def sample_episode(self, scene: Scene, rng: np.random.Generator) -> Episode:
        before, *targets = self._route(scene)
        d, a = self.start_jitter
        start = before + np.array([rng.uniform(-d, d), rng.uniform(-d, d), rng.uniform(-a, a)])
        start[2] = wrap_angle(start[2])
        return Episode(home=targets[-1], start=start, waypoints=tuple(targets[:-1]))

    def extra_info(self, ctx: TaskContext) -> dict:
        return {"target_index": ctx.goal_index(), "target_errors": list(self.goal_errors)}
