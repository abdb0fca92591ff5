"""Reaching a sequence of goal poses: the episode logic shared by homing and routes."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, fields

from homing_gym.tasks.context import TaskContext
from homing_gym.tasks.base import Task
from homing_gym.validation import is_real


SUCCESS_MODES = ("reach", "stop")
#: Largest ``success_radius`` (m) any task takes: a goal judged from farther is no longer
#: homing (the papers' radii are 0.1-0.3 m). Tasks also refuse a radius that an episode
#: could start within (``check_scene``).
MAX_SUCCESS_RADIUS = 2.0


def checked_success_radius(value) -> float:
    """``success_radius`` (metres) as a float if it is a number in
    ``(0, MAX_SUCCESS_RADIUS]``; else ``ValueError`` naming the value and the range."""
    if not (is_real(value) and 0 < value <= MAX_SUCCESS_RADIUS):
        raise ValueError(f"success_radius must be a number of metres in "
                         f"(0, {MAX_SUCCESS_RADIUS:g}] (a goal judged from farther is no "
                         f"longer homing), got {value!r}")
    return float(value)


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

    ``success_on="stop"`` (default): the agent itself signals arrival with the stop action;
    the goal is then left with the distance at the stop as its error (the accuracy
    protocol of the papers, where the method decides it has arrived).
    ``success_on="reach"``: a goal is reached as soon as the robot centre is within
    ``success_radius`` metres of it. After
    the last goal the episode terminates; it is a success if that goal was within
    ``success_radius``. ``goal_errors`` holds the distance (metres) at which each goal was
    left.
    """

    def __init__(self, success_radius: float = 0.15, success_on: str = "stop",
                 reward: RewardConfig | Mapping[str, float] = RewardConfig()):
        self.success_radius = checked_success_radius(success_radius)
        if success_on not in SUCCESS_MODES:
            raise ValueError(f"unknown success_on {success_on!r}; allowed: {SUCCESS_MODES}")
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
