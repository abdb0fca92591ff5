"""Long-range homing (Bekris, Argyros & Kavraki §3 and §5, Fig. 12): the robot leaves
home along a route of about 8 m driven by the env while the agent watches, then must
return home from the end of the route by itself.

Phase 0 (outbound): the env follows a seeded polyline route from the start (home) with
a simple pursuit law at ``outbound_speed`` m/s and ``outbound_yaw_rate`` rad/s (turning on
the spot first when a waypoint is more than 0.2 rad off the heading); the agent's
actions are validated and ignored, no reward is paid and the episode cannot end. Phase 1
(homing) starts once the last waypoint is reached: from then on the episode is
:class:`~homing_gym.tasks.goal_reaching.GoalReachingTask` with home as its only goal.
"""

from __future__ import annotations

import math

import numpy as np
from gymnasium import spaces

from homing_gym.geometry import bearing_to
from homing_gym.observations import ObservationKey, constant_key
from homing_gym.sim.robot import RobotConfig
from homing_gym.scenes.base import Scene
from homing_gym.tasks.context import TaskContext
from homing_gym.tasks.base import Episode, random_route, sample_free_pose
from homing_gym.tasks.goal_reaching import GoalReachingTask, RewardConfig
from homing_gym.validation import is_real, require_positive


OUTBOUND, HOMING = 0, 1
#: A waypoint counts as passed within this distance (m).
WAYPOINT_RADIUS = 0.05
#: Heading error (rad) above which the outbound driver turns on the spot.
TURN_FIRST = 0.2


class LongRangeHomingTask(GoalReachingTask):
    """Outbound route then homing (module docstring). The robot starts where the previous
    episode may have ended (the same seed's home, e.g. after a one-step episode); PyBullet
    keeps contact points cached there by proximity, with their warm-start impulses, which
    would make this episode depend on the last: ``fresh_contacts`` clears them. ``route_length`` (m, in
    ``[0.5, 30]``), ``outbound_speed`` (m/s) and ``outbound_yaw_rate`` (rad/s, both at
    most the robot's limits, checked by the env), ``clearance_margin`` (m) of the home
    pose and of the route; ``success_radius``, ``success_on`` and ``reward`` as in
    :class:`GoalReachingTask`."""

    fresh_contacts = True
    drives_robot = True

    def __init__(self, route_length: float = 8.0, outbound_speed: float = 0.15,
                 outbound_yaw_rate: float = 0.5, success_radius: float = 0.2,
                 success_on: str = "stop", reward: RewardConfig = RewardConfig(),
                 clearance_margin: float = 0.3):
        if not (is_real(route_length) and 0.5 <= route_length <= 30):
            raise ValueError(f"route_length must be in [0.5, 30] metres, got {route_length!r}")
        require_positive("outbound_speed", outbound_speed, "m/s")
        require_positive("outbound_yaw_rate", outbound_yaw_rate, "rad/s")
        require_positive("clearance_margin", clearance_margin, "metres")
        super().__init__(success_radius, success_on, reward)
        self.route_length = float(route_length)
        self.outbound_speed = float(outbound_speed)
        self.outbound_yaw_rate = float(outbound_yaw_rate)
        self.clearance_margin = float(clearance_margin)
        self.route = np.zeros((0, 2))
        self.phase = OUTBOUND
        self.waypoint = 1
        self.outbound_steps = 0

    def check_scene(self, scene: Scene) -> None:
        width, depth = scene.size
        if min(width, depth) < 4 * self.clearance_margin:
            raise ValueError(f"scene {scene.name!r} of size {width:.2f} x {depth:.2f} m is "
                             f"too small for routes {self.clearance_margin} m clear of its "
                             f"walls")

    def check_limits(self, rc: RobotConfig) -> None:
        """``ValueError`` unless the outbound speeds are within the robot's limits."""
        if self.outbound_speed > rc.max_speed or self.outbound_yaw_rate > rc.max_yaw_rate:
            raise ValueError(f"outbound_speed {self.outbound_speed} m/s and "
                             f"outbound_yaw_rate {self.outbound_yaw_rate} rad/s must not "
                             f"exceed max_speed {rc.max_speed} and max_yaw_rate "
                             f"{rc.max_yaw_rate}")

    def sample_episode(self, scene: Scene, rng: np.random.Generator) -> Episode:
        home = sample_free_pose(scene, rng, self.clearance_margin)
        return Episode(home=home, start=home.copy())

    def on_reset(self, ctx: TaskContext) -> None:
        super().on_reset(ctx)
        self.route = random_route(ctx.scene(), ctx.episode().start, ctx.rng(),
                                self.route_length, self.clearance_margin)
        self.phase, self.waypoint, self.outbound_steps = OUTBOUND, 1, 0

    def command(self, ctx: TaskContext, v: float, w: float,
                stopped: bool) -> tuple[float, float, bool]:
        """Outbound: the env's own pursuit command (normalised); homing: the agent's."""
        if self.phase == HOMING:
            return v, w, stopped
        rc = ctx.robot
        err = bearing_to(ctx.pose(), self.route[self.waypoint])
        yaw = float(np.clip(3.0 * err, -self.outbound_yaw_rate, self.outbound_yaw_rate))
        speed = 0.0 if abs(err) > TURN_FIRST else self.outbound_speed
        return speed / rc.max_speed, yaw / rc.max_yaw_rate, False

    def step_outcome(self, ctx: TaskContext, collision: bool, stopped: bool):
        if self.phase == HOMING:
            return super().step_outcome(ctx, collision, stopped)
        self.outbound_steps += 1
        if math.dist(ctx.pose()[:2], self.route[self.waypoint]) < WAYPOINT_RADIUS:
            self.waypoint += 1
            if self.waypoint == len(self.route):
                self.phase = HOMING
                self._prev_distance = ctx.distance_to_goal()
        rewards = {k: 0.0 for k in ("progress", "waypoint", "success", "collision", "time",
                                    "wrong_stop")}
        return rewards, False, False

    def observation_keys(self) -> dict[str, ObservationKey]:
        return {"phase": constant_key(spaces.Discrete(2), lambda: np.int64(self.phase))}

    def extra_info(self, ctx: TaskContext) -> dict:
        return {"phase": self.phase, "outbound_steps": self.outbound_steps,
                "route": self.route.copy()}
