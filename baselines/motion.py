"""Turning a paper-style move (direction + step length) into differential-drive actions.

Visual-homing papers express each decision as a *home vector*: a direction of motion
(radians, in the robot frame, counter-clockwise from the heading) and a step length
(metres). :class:`MotionHelper` turns such a :class:`Move` into the sequence of env actions
that executes it open loop, for both action types of the env, in one of two styles:

* ``"turn_then_drive"``: turn on the spot by the direction, then drive straight;
* ``"pursuit"``: a smooth circular arc through the target point (turn and drive at once;
  turns on the spot first only when the target is more than 45 degrees off the heading);
* ``"reversing"``: turn then drive, but a direction more than 90 degrees off the heading is
  driven backwards after turning the tail towards it (a turn of at most 90 degrees instead
  of up to 180): a controller whose direction flips back and forth, as a vector field's
  does along a curve it converges onto, then spends one or two actions per flip instead of
  a half turn.

With discrete actions both ``"pursuit"`` and ``"reversing"`` turn then drive: the discrete
set has neither arcs nor a backward action.

On a synchro-drive robot (``drive="synchro"``: it translates without turning, as Hong et
al.'s did) either style translates straight along the direction, and a move of length
0 does nothing (the body cannot turn).

Moves are executed open loop; on the simulated robot a turn overshoots by a few degrees
(inertia), so controllers should decide again after short steps.

The helper knows only the robot's command limits (:class:`MotionSpec`), never its pose.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from homing_gym.actions import DiscreteAction
from homing_gym.geometry import wrap_angle

MOTION_STYLES = ("turn_then_drive", "pursuit", "reversing")


@dataclass(frozen=True)
class Move:
    """One decision: rotate towards ``direction`` (radians, robot frame, CCW, in
    ``(-pi, pi]``) and travel ``distance`` metres that way (0: turn on the spot)."""

    direction: float
    distance: float

    def __post_init__(self) -> None:
        if not (math.isfinite(self.direction) and math.isfinite(self.distance)
                and self.distance >= 0):
            raise ValueError(f"a Move needs a finite direction and a distance >= 0 metres, "
                             f"got direction={self.direction!r}, distance={self.distance!r}")


@dataclass(frozen=True)
class MotionSpec:
    """The command interface of the env: what an action means physically.

    ``max_speed`` (m/s) and ``max_yaw_rate`` (rad/s) scale the normalised continuous
    action; each action lasts ``control_period`` seconds; a continuous action with both
    components below ``stop_threshold`` in magnitude is the stop signal.
    """

    action_type: str = "continuous"
    max_speed: float = 0.3
    max_yaw_rate: float = 1.5
    control_period: float = 0.1
    stop_threshold: float = 0.05
    drive: str = "differential"

    @classmethod
    def from_env(cls, env) -> "MotionSpec":
        """Read the command interface (not the state) of a homing-gym env."""
        u = env.unwrapped
        return cls(action_type=u.action_type, max_speed=u.robot_config.max_speed,
                   max_yaw_rate=u.robot_config.max_yaw_rate,
                   control_period=u.control_period, stop_threshold=u.stop_threshold,
                   drive=u.robot_config.drive)

    @property
    def step_turn(self) -> float:
        """Largest turn (radians) in one control period."""
        return self.max_yaw_rate * self.control_period

    @property
    def step_distance(self) -> float:
        """Largest forward travel (metres) in one control period."""
        return self.max_speed * self.control_period


#: Discrete actions of the env (:class:`homing_gym.actions.DiscreteAction`).
FORWARD, LEFT, RIGHT, STOP = (DiscreteAction.FORWARD, DiscreteAction.TURN_LEFT,
                              DiscreteAction.TURN_RIGHT, DiscreteAction.STOP)


class MotionHelper:
    """Plans the env actions that execute a :class:`Move` (open loop)."""

    def __init__(self, spec: MotionSpec = MotionSpec(), style: str = "turn_then_drive",
                 pursuit_gain: float = 2.0):
        if style not in MOTION_STYLES:
            raise ValueError(f"unknown motion style {style!r}; allowed: {MOTION_STYLES}")
        if spec.action_type not in ("continuous", "discrete"):
            raise ValueError(f"unknown action_type {spec.action_type!r}")
        if spec.drive == "synchro" and spec.action_type != "continuous":
            raise ValueError("a synchro drive takes continuous actions")
        self.spec = spec
        self.style = style
        self.pursuit_gain = float(pursuit_gain)
        #: Direction (radians, CCW, robot frame when the move ends) in which the last
        #: planned move translated: 0 driving forward, pi backwards, the move's own
        #: direction on a synchro drive (the body keeps its heading); None before any
        #: translation.
        self.travel: float | None = None

    def reset(self) -> None:
        """Start a new episode: no move has translated the robot yet."""
        self.travel = None

    def stop_action(self):
        """The env's stop signal: discrete action 3 or the continuous action (0, 0)."""
        if self.spec.action_type == "discrete":
            return STOP
        return np.zeros(2, np.float32)

    def plan(self, move: Move) -> list:
        """Actions that carry out ``move``; empty if the move is below one command's
        resolution (it would otherwise read as a stop)."""
        actions, travel = self._plan(move)
        if move.distance > 0 and actions:
            self.travel = travel
        return actions

    def _plan(self, move: Move) -> tuple[list, float]:
        """The actions and the direction of travel at the end of the move (see
        :attr:`travel`)."""
        if self.spec.drive == "synchro":
            return self._translate(move), float(wrap_angle(move.direction))
        if self.style == "pursuit" and self.spec.action_type == "continuous" \
                and move.distance > 0:
            return self._pursuit(move), 0.0
        direction = wrap_angle(move.direction)
        if self.style == "reversing" and self.spec.action_type == "continuous" \
                and move.distance > 0 and abs(direction) > math.pi / 2:
            return self._turn(wrap_angle(direction - math.pi)) + [
                -action for action in self._drive(move.distance)], math.pi
        return self._turn(direction) + self._drive(move.distance), 0.0

    def _translate(self, move: Move) -> list:
        """Synchro drive: straight along ``move.direction`` at constant speed, the
        normalised action being the body-frame velocity."""
        s = self.spec
        n = math.ceil(move.distance / s.step_distance - 1e-9)
        if n == 0:
            return []
        speed = move.distance / (n * s.step_distance)
        action = np.array([speed * math.cos(move.direction), speed * math.sin(move.direction)],
                          np.float32)
        if np.max(np.abs(action)) < s.stop_threshold:
            return []
        return [action.copy() for _ in range(n)]

    # -- turn then drive -----------------------------------------------------------------
    def _turn(self, angle: float) -> list:
        s = self.spec
        if s.action_type == "discrete":
            n = int(round(abs(angle) / s.step_turn))
            return [LEFT if angle > 0 else RIGHT] * n
        n = math.ceil(abs(angle) / s.step_turn - 1e-9)
        if n == 0:
            return []
        w = angle / (n * s.step_turn)
        if abs(w) < s.stop_threshold:
            return []
        return [np.array([0.0, w], np.float32) for _ in range(n)]

    def _drive(self, distance: float) -> list:
        s = self.spec
        if s.action_type == "discrete":
            return [FORWARD] * int(round(distance / s.step_distance))
        n = math.ceil(distance / s.step_distance - 1e-9)
        if n == 0:
            return []
        v = distance / (n * s.step_distance)
        if v < s.stop_threshold:
            return []
        return [np.array([v, 0.0], np.float32) for _ in range(n)]

    # -- pursuit ---------------------------------------------------------------------------
    def _pursuit(self, move: Move, max_bearing: float = math.pi / 4) -> list:
        """Turn on the spot only until the target is within ``max_bearing`` of the
        heading, then follow the one circular arc tangent to the heading that ends on the
        target (constant forward speed and yaw rate)."""
        s = self.spec
        bearing = wrap_angle(move.direction)
        pre = math.copysign(max(0.0, abs(bearing) - max_bearing), bearing)
        b = bearing - pre  # remaining bearing, |b| <= max_bearing
        arc = move.distance if abs(b) < 1e-9 else move.distance * b / math.sin(b)
        n = max(math.ceil(arc / s.step_distance - 1e-9), math.ceil(abs(2 * b) / s.step_turn - 1e-9))
        if n == 0:
            return self._turn(pre)
        v, w = arc / (n * s.step_distance), 2 * b / (n * s.step_turn)
        if abs(v) < s.stop_threshold and abs(w) < s.stop_threshold:
            return self._turn(pre)
        return self._turn(pre) + [np.array([v, w], np.float32) for _ in range(n)]


def unicycle_step(pose, v: float, w: float, spec: MotionSpec) -> tuple[float, float, float]:
    """Exact unicycle motion over one control period from ``pose`` = (x, y, yaw) under the
    normalised command (v, w)."""
    x, y, yaw = pose
    dt = spec.control_period
    vv, ww = v * spec.max_speed, w * spec.max_yaw_rate
    if abs(ww) < 1e-9:
        return x + vv * dt * math.cos(yaw), y + vv * dt * math.sin(yaw), yaw
    return (x + vv / ww * (math.sin(yaw + ww * dt) - math.sin(yaw)),
            y - vv / ww * (math.cos(yaw + ww * dt) - math.cos(yaw)), yaw + ww * dt)


def integrate(actions: list, spec: MotionSpec) -> np.ndarray:
    """Ideal unicycle pose ``(x, y, yaw)`` reached from the origin by ``actions``
    (the kinematic model, for tests and dead reckoning)."""
    pose = (0.0, 0.0, 0.0)
    for a in actions:
        v, w = DiscreteAction(int(a)).command if spec.action_type == "discrete" else (a[0], a[1])
        pose = unicycle_step(pose, float(v), float(w), spec)
    return np.array([pose[0], pose[1], wrap_angle(pose[2])])
