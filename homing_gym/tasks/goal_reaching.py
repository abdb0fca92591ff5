"""Reaching a sequence of goal poses: the episode logic shared by homing and routes."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, fields

from homing_gym.tasks.context import TaskContext
from homing_gym.tasks.base import Task
from homing_gym.validation import is_real, require_positive


SUCCESS_MODES = ("reach", "stop")


@dataclass(frozen=True)
class RewardConfig:
    """Reward weights. ``progress`` multiplies the decrease of the distance to the current
    goal (per metre: potential-based shaping with potential ``-distance``, restarted when
    the goal changes); ``waypoint`` is paid for each intermediate goal of a route,
    ``success`` once on success; ``collision`` is subtracted on every step with contact,
    ``time`` on every step, ``wrong_stop`` each time the agent stops outside the success
    radius (``success_on="stop"``; 0 by default: such a stop already forfeits the progress
    still to be made, but an untrained policy stops at random and learns that stopping
    anywhere ends the time penalty)."""

    progress: float = 1.0
    waypoint: float = 1.0
    success: float = 10.0
    collision: float = 0.1
    time: float = 0.01
    wrong_stop: float = 0.0

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if not is_real(value):
                raise ValueError(f"reward weight {f.name} must be a finite number, got {value!r}")

    @classmethod
    def from_value(cls, value: "RewardConfig | Mapping[str, float]") -> "RewardConfig":
        """A ``RewardConfig`` from itself or from a mapping of some of its fields (as
        YAML or JSON env kwargs give it, e.g. ``{"progress": 10}``)."""
        if isinstance(value, cls):
            return value
        if not isinstance(value, Mapping):
            raise ValueError(f"reward must be a RewardConfig or a mapping of its fields, "
                             f"got {value!r}")
        allowed = [f.name for f in fields(cls)]
        unknown = sorted(set(value) - set(allowed))
        if unknown:
            raise ValueError(f"unknown reward terms {unknown}; allowed: {allowed}")
        return cls(**value)


class GoalReachingTask(Task):
    """Visit the episode's goals in order (``Episode.goals``: waypoints, then home).

    ``success_on="reach"``: a goal is reached as soon as the robot centre is within
    ``success_radius`` metres of it. ``success_on="stop"``: the agent itself signals arrival
    with the stop action; the goal is then left with the distance at the stop as its error
    (the accuracy protocol of the papers, where the method decides it has arrived). After
    the last goal the episode terminates; it is a success if that goal was within
    ``success_radius``. ``goal_errors`` holds the distance (metres) at which each goal was
    left.
    """

    def __init__(self, success_radius: float = 0.15, success_on: str = "reach",
                 reward: RewardConfig | Mapping[str, float] = RewardConfig()):
        require_positive("success_radius", success_radius, "metres")
        if success_on not in SUCCESS_MODES:
            raise ValueError(f"unknown success_on {success_on!r}; allowed: {SUCCESS_MODES}")
        self.success_radius = float(success_radius)
        self.success_on = success_on
        self.reward = RewardConfig.from_value(reward)
        self.goal_errors: list[float] = []
        self._prev_distance = 0.0

    def on_reset(self, ctx: TaskContext) -> None:
        self._prev_distance = ctx.distance_to_goal()
        self.goal_errors = []

    def step_outcome(self, ctx: TaskContext, collision: bool, stopped: bool):
        distance = ctx.distance_to_goal()
        within = distance < self.success_radius
        arrived = stopped if self.success_on == "stop" else within
        last = ctx.goal_index() == len(ctx.episode().goals) - 1
        rewards = {
            "progress": self.reward.progress * (self._prev_distance - distance),
            "waypoint": 0.0,
            "success": 0.0,
            "collision": -self.reward.collision if collision else 0.0,
            "time": -self.reward.time,
            "wrong_stop": -self.reward.wrong_stop if arrived and not within else 0.0,
        }
        self._prev_distance = distance
        terminated = success = False
        if arrived:
            self.goal_errors.append(distance)
            if last:
                terminated, success = True, within
                rewards["success"] = self.reward.success if success else 0.0
            else:
                rewards["waypoint"] = self.reward.waypoint if within else 0.0
                ctx.advance_goal()
                self._prev_distance = ctx.distance_to_goal()
        return rewards, terminated, success
