"""A kinematic robot (``motion="kinematic"``): the unicycle model without PyBullet's
dynamics, for training where an env step's physics would cost more than its picture.

The wheels follow the commanded speeds with the same ramp as the simulated motors
(:meth:`homing_gym.sim.robot.Robot.update_motors`: at most ``wheel_acceleration`` of
rim acceleration), at every sub-step of ``time_step`` seconds, and the body moves by
the unicycle model (forward speed the wheels' mean rim speed, yaw rate their difference
over the wheel separation; midpoint integration). Where it differs from PyBullet's
robot (the default, ``motion="pybullet"``):

* **No dynamics**: no wheel slip, inertia, bumps or caster drag; on free floor it drives
  the commanded arcs exactly. After 1.5 s of one command from rest PyBullet's robot is
  within 1 cm of it and has turned 2-4 degrees less in turns (its wheels slip a little:
  ``tests/homing_gym/test_kinematic.py``).
* **Obstacles stop it**: the body is a disc of ``body_radius``; a sub-step that would
  bring it nearer than that to a wall, landmark, colliding mesh part or the bounds
  (:func:`homing_gym.scenes.base.clearances`, the floor plan the tasks and paths use) is
  not taken, nor any later one of that control period, and the step counts a collision.
  It does not slide along walls or get pushed back as PyBullet's contact solver does; a
  move that increases the clearance is always taken, so a robot put down close to a wall
  can drive away from it.
* **Encoders**: the wheel angles advance by the commanded (ramped) wheel speeds even
  when an obstacle stops the body (wheels slipping against a wall), so the odometry
  drifts there as a real robot's would.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from homing_gym.geometry import wrap_angle
from homing_gym.scenes.base import Scene, clearances
from homing_gym.sim.robot import RobotConfig, wheel_speeds


class KinematicRobot:
    """The robot of a :class:`~homing_gym.sim.simulator.Simulator` with
    ``motion="kinematic"``, in ``scene``; the interface of
    :class:`~homing_gym.sim.robot.Robot` that the env uses."""

    synchro = False

    def __init__(self, scene: Scene, config: RobotConfig):
        if config.drive != "differential":
            raise ValueError(f"motion='kinematic' drives a differential robot only, got "
                             f"drive={config.drive!r}")
        self.scene, self.config = scene, config
        self._pose = np.zeros(3)
        self._angles = np.zeros(2)
        self._current = [0.0, 0.0]
        self._target = [0.0, 0.0]

    def set_pose(self, x: float, y: float, yaw: float) -> None:
        """Put the robot at a pose, at rest."""
        self._pose = np.array([float(x), float(y), wrap_angle(float(yaw))])
        self._current = [0.0, 0.0]
        self._target = [0.0, 0.0]
        self._angles = np.zeros(2)

    def drive(self, v: float, w: float) -> None:
        """Command forward speed ``v`` (m/s) and yaw rate ``w`` (rad/s, CCW)."""
        self._target = list(wheel_speeds(v, w, self.config))

    def move(self, substeps: int, time_step: float) -> bool:
        """Drive ``substeps`` sub-steps of ``time_step`` seconds; True if an obstacle
        stopped the body."""
        c = self.config
        limit = c.wheel_acceleration / c.wheel_radius * time_step
        current = np.array(self._current, np.float64)
        path, turned = _unicycle_path(self._pose, current, np.array(self._target, np.float64),
                                      limit, time_step, substeps, c.wheel_radius,
                                      c.wheel_separation)
        self._current = current.tolist()
        self._angles += turned
        free = clearances(self.scene, np.vstack([self._pose[:2], path[:, :2]]))
        blocked = (free[1:] < c.body_radius) & (free[1:] < free[:-1])
        k = int(np.argmax(blocked)) if blocked.any() else substeps
        if k > 0:
            x, y, yaw = path[k - 1]
            self._pose = np.array([x, y, wrap_angle(yaw)])
        return k < substeps

    def pose(self) -> np.ndarray:
        """The pose ``(x, y, yaw)`` (metres, radians)."""
        return self._pose.copy()

    def encoders(self) -> np.ndarray:
        """(left, right) wheel angles (radians) since the robot was put down."""
        return self._angles.copy()

    wheel_angles = encoders


@njit(cache=True)
def _unicycle_path(pose: np.ndarray, current: np.ndarray, target: np.ndarray, limit: float,
                   dt: float, n: int, wheel_radius: float, separation: float
                   ) -> tuple[np.ndarray, np.ndarray]:
    """The poses ``(n, 3)`` after each of ``n`` sub-steps of ``dt`` seconds from ``pose``
    with the wheel speeds ``current`` (rad/s, updated in place) ramped towards ``target``
    by at most ``limit`` a sub-step, and the wheel angles turned (radians)."""
    path = np.empty((n, 3))
    turned = np.zeros(2)
    x, y, yaw = pose[0], pose[1], pose[2]
    for k in range(n):
        for side in range(2):
            current[side] += max(-limit, min(limit, target[side] - current[side]))
            turned[side] += current[side] * dt
        v = (current[0] + current[1]) / 2 * wheel_radius
        w = (current[1] - current[0]) * wheel_radius / separation
        mid = yaw + w * dt / 2
        x += v * dt * math.cos(mid)
        y += v * dt * math.sin(mid)
        yaw += w * dt
        path[k, 0], path[k, 1], path[k, 2] = x, y, yaw
    return path, turned
