"""``oracle``: drives home along the true shortest path, reading the true pose.

The upper bound of every comparison and a check of the harness: it is the one controller
that is given the env (``needs_env = True``) and reads ``env.unwrapped.pose``,
``episode.home`` and ``scene``. It plans a collision-free shortest path around obstacles
(:func:`homing_gym.paths.shortest_path`) once per episode and, at every decision, moves
at most ``step_length`` metres towards the farthest path waypoint it can see; with
``success_on="stop"`` it stops once within ``arrive_tolerance`` of home, after turning to
the home heading if ``align_heading``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

from homing_baselines.base import Controller
from homing_baselines.motion import Move
from homing_gym.paths import NoPathError, segment_free, shortest_path
from homing_gym.geometry import bearing_to, wrap_angle
from homing_gym.scenes.base import clearance
from homing_gym.validation import require_positive


@dataclass
class OracleController(Controller):
    """Parameters (metres, radians): ``step_length`` longest move between decisions;
    ``arrive_tolerance`` distance to home at which it stops; ``align_heading`` turn to the
    home heading before stopping, within ``heading_tolerance``; ``margin`` clearance kept
    from obstacles when planning."""

    step_length: float = 0.1
    arrive_tolerance: float = 0.03
    align_heading: bool = True
    heading_tolerance: float = 0.05
    margin: float = 0.22

    needs_env: ClassVar[bool] = True

    def validate(self) -> None:
        for key in ("step_length", "arrive_tolerance", "heading_tolerance", "margin"):
            value = getattr(self, key)
            require_positive(f"oracle: {key}", value)

    def attach_env(self, env) -> None:
        """Give the oracle its privileged handle on the (unwrapped) env."""
        self._env = env.unwrapped

    def on_reset(self) -> None:
        self._path: list | None = None

    def decide(self, observation) -> Move | None:
        env = getattr(self, "_env", None)
        if env is None:
            raise RuntimeError("oracle: attach_env(env) must be called before predict()")
        pose, home, scene = env.pose, env.episode.home, env.scene
        distance = math.hypot(home[0] - pose[0], home[1] - pose[1])
        if distance < self.arrive_tolerance:
            turn = wrap_angle(home[2] - pose[2])
            if self.align_heading and abs(turn) > self.heading_tolerance:
                return Move(turn, 0.0)
            return None
        return self.move_to(pose, self.waypoint(scene, pose, home))

    def move_to(self, pose, target) -> Move:
        """The move from ``pose`` towards the floor point ``target``: turn to it, drive at
        most ``step_length`` metres."""
        return Move(bearing_to(pose, target),
                    min(self.step_length, math.hypot(target[0] - pose[0], target[1] - pose[1])))

    def waypoint(self, scene, pose, home) -> tuple[float, float]:
        """Home if the straight way from ``pose`` is free, else the farthest visible
        waypoint of the shortest path (planned once per episode, replanned when lost)."""
        xy = (float(pose[0]), float(pose[1]))
        # slack for drift off the planned path, and for a robot already pushed close to
        # an obstacle (never below the body radius plus a contact margin)
        see = max(min(self.margin, clearance(scene, xy)) - 0.02, 0.17)
        if segment_free(scene, xy, home, min(self.margin, see + 0.02)):
            return home[0], home[1]
        for attempt in range(2):
            if self._path is None or attempt == 1:
                try:
                    self._path = shortest_path(scene, xy, home, self.margin)
                except NoPathError:
                    return home[0], home[1]
            for waypoint in reversed(self._path[1:]):
                if segment_free(scene, xy, waypoint, see):
                    return waypoint
        return self._path[1]
