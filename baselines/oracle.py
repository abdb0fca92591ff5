"""``oracle``: drives to each goal along the true shortest path, reading the true pose.

The upper bound of every comparison and a check of the harness: it is the one controller
that is given the env (``needs_env = True``) and reads ``env.unwrapped.pose``,
``goal_pose`` (home, or the current target of a route, which the env advances as targets
are reached), ``scene`` and ``task``. It plans the shortest path around obstacles for a
disc of the task's ``path_radius`` (:func:`homing_gym.paths.shortest_path`: the path
SPL measures, which every episode the task draws has) once per goal and, at every
decision, moves at most ``step_length`` metres towards the farthest path waypoint it can
see; with ``success_on="stop"`` it stops once within ``arrive_tolerance`` of the goal,
after turning to the goal heading if ``align_heading``: at home, and at every target of
a route in turn.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

from homing_baselines.base import Controller
from homing_baselines.motion import Move
from homing_gym.paths import BODY_RADIUS, segment_free, shortest_path
from homing_gym.geometry import bearing_to, wrap_angle
from homing_gym.scenes.base import clearance
from homing_gym.validation import require_positive


@dataclass
class OracleController(Controller):
    """Parameters (metres, radians): ``step_length`` longest move between decisions;
    ``arrive_tolerance`` distance to the goal at which it stops; ``align_heading`` turn to
    the goal heading before stopping, within ``heading_tolerance``."""

    step_length: float = 0.1
    arrive_tolerance: float = 0.03
    align_heading: bool = True
    heading_tolerance: float = 0.05

    needs_env: ClassVar[bool] = True
    privileged: ClassVar[str] = "true poses and the world's map"

    def validate(self) -> None:
        for key in ("step_length", "arrive_tolerance", "heading_tolerance"):
            value = getattr(self, key)
            require_positive(f"oracle: {key}", value)

    def attach_env(self, env) -> None:
        """Give the oracle its privileged handle on the (unwrapped) env."""
        self._env = env.unwrapped

    def on_reset(self) -> None:
        self._path: list | None = None
        self._path_goal: tuple[float, float] | None = None

    def decide(self, observation) -> Move | None:
        env = getattr(self, "_env", None)
        if env is None:
            raise RuntimeError("oracle: attach_env(env) must be called before predict()")
        pose, goal, scene = env.pose, env.goal_pose, env.scene
        distance = math.hypot(goal[0] - pose[0], goal[1] - pose[1])
        if distance < self.arrive_tolerance:
            turn = wrap_angle(goal[2] - pose[2])
            if self.align_heading and abs(turn) > self.heading_tolerance:
                return Move(turn, 0.0)
            return None
        return self.move_to(pose, self.waypoint(scene, pose, goal))

    def move_to(self, pose, target) -> Move:
        """The move from ``pose`` towards the floor point ``target``: turn to it, drive at
        most ``step_length`` metres."""
        return Move(bearing_to(pose, target),
                    min(self.step_length, math.hypot(target[0] - pose[0], target[1] - pose[1])))

    def waypoint(self, scene, pose, goal) -> tuple[float, float]:
        """The goal if the straight way from ``pose`` is free, else the farthest visible
        waypoint of the shortest path (planned once per goal, replanned when lost).
        :class:`~homing_gym.paths.NoPathError` where none leads to the goal (an episode
        the task did not draw: start or home given as reset options)."""
        xy, goal_xy = (float(pose[0]), float(pose[1])), (float(goal[0]), float(goal[1]))
        radius = self._env.task.path_radius
        # slack for drift off the planned path, and for a robot already pushed close to
        # an obstacle (never below the body radius plus a contact margin, or the radius)
        see = max(min(radius, clearance(scene, xy)) - 0.02, min(radius, BODY_RADIUS + 0.01))
        if segment_free(scene, xy, goal_xy, min(radius, see + 0.02)):
            return goal_xy
        for attempt in range(2):
            if self._path is None or self._path_goal != goal_xy or attempt == 1:
                self._path = shortest_path(scene, xy, goal_xy, radius)
                self._path_goal = goal_xy
            for waypoint in reversed(self._path[1:]):
                if segment_free(scene, xy, waypoint, see):
                    return waypoint
        return self._path[1]
