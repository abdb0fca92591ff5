"""The robot: URDF loading, its two drives and their odometry.

Frame conventions (used everywhere in homing-gym): world x, y on the floor, z up;
a pose is ``(x, y, yaw)`` in metres and radians, yaw counter-clockwise from world +x.
The robot's own frame has x forward, y to the left.

Drives (``RobotConfig.drive``):

* ``"differential"`` (default): two driven wheels and a caster; the command is a forward
  speed and a yaw rate (unicycle model), executed by the wheel motors.
* ``"synchro"``: a synchro-drive base, as Hong et al.'s robot (1991, §3: "the robot does
  not rotate"): all wheels steer together, so the body translates in any direction and
  keeps its heading. The command is a velocity ``(vx, vy)`` in the body frame. Simulated
  kinematically: every physics step the base is given the commanded velocity (ramped by
  ``wheel_acceleration``, as the differential motors are), no angular velocity, and
  frictionless wheels; walls and landmarks still stop it (the contact solver). Its
  odometry integrates the commanded travel (the driven wheels turn as commanded; pushed
  against a wall they slip, as real wheels do), each increment scaled by
  ``1 + N(0, noise)``, at the fixed heading.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from importlib import resources

import numpy as np
import pybullet as p
from pybullet_utils.bullet_client import BulletClient

from homing_gym.geometry import wrap_angle
from homing_gym.validation import require_number

URDF_PATH = str(resources.files("homing_gym") / "assets" / "robot.urdf")
DRIVES = ("differential", "synchro")
#: Largest ``odometry_noise``: a standard deviation of 100 % of each wheel increment.
MAX_ODOMETRY_NOISE = 1.0


#: PyBullet's default top speed of a joint (rad/s, ``maxJointVelocity``): wheel motors
#: asked for more reach only this.
MAX_WHEEL_SPEED = 100.0


@dataclass(frozen=True)
class RobotConfig:
    """Physical constants of the robot (metres, seconds, radians).

    ``max_speed`` and ``max_yaw_rate`` scale the normalised action ``(v, w) in [-1, 1]^2``.
    The motor controller ramps each wheel's rim speed by at most ``wheel_acceleration``
    (m/s^2), as real drive controllers do; without the ramp, abrupt command changes make
    the wheels slip and the encoders lie.
    """

    body_radius: float = 0.16
    wheel_radius: float = 0.035
    wheel_separation: float = 0.23
    camera_height: float = 0.30
    base_height: float = 0.055
    max_speed: float = 0.3
    max_yaw_rate: float = 1.5
    wheel_torque: float = 2.0
    wheel_acceleration: float = 2.0
    drive: str = "differential"

    def __post_init__(self) -> None:
        if self.drive not in DRIVES:
            raise ValueError(f"unknown drive {self.drive!r}; allowed: {DRIVES}")
        if self.drive == "differential" and self.max_wheel_speed > MAX_WHEEL_SPEED:
            raise ValueError(
                f"max_speed {self.max_speed!r} m/s with max_yaw_rate {self.max_yaw_rate!r} "
                f"rad/s asks the wheels for {self.max_wheel_speed:.0f} rad/s; at most "
                f"{MAX_WHEEL_SPEED:.0f} rad/s (PyBullet's joint speed limit; a faster command "
                f"would be cut short): max_speed + max_yaw_rate * "
                f"{self.wheel_separation / 2:g} <= "
                f"{MAX_WHEEL_SPEED * self.wheel_radius:g} m/s")

    @property
    def max_wheel_speed(self) -> float:
        """Largest wheel angular speed (rad/s) the unicycle model can ask for."""
        return (self.max_speed + self.max_yaw_rate * self.wheel_separation / 2) / self.wheel_radius


def wheel_speeds(v: float, w: float, config: RobotConfig) -> tuple[float, float]:
    """Unicycle model: forward speed ``v`` (m/s) and yaw rate ``w`` (rad/s, CCW)
    to (left, right) wheel angular speeds in rad/s."""
    half = config.wheel_separation / 2
    return (v - w * half) / config.wheel_radius, (v + w * half) / config.wheel_radius


class Robot:
    """The robot body inside one :class:`~homing_gym.sim.simulator.Simulator` client."""

    def __init__(self, client: BulletClient, config: RobotConfig = RobotConfig()):
        self.client = client
        self.config = config
        self.body_id = client.loadURDF(URDF_PATH, [0, 0, config.base_height], useFixedBase=False)
        names = {
            client.getJointInfo(self.body_id, j)[1].decode(): j
            for j in range(client.getNumJoints(self.body_id))
        }
        self.wheel_joints = [names["left_wheel_joint"], names["right_wheel_joint"]]
        self.caster_link = names["caster_joint"]
        for j in self.wheel_joints:
            client.changeDynamics(self.body_id, j, lateralFriction=1.0, spinningFriction=0.0,
                                  rollingFriction=0.0)
        client.changeDynamics(self.body_id, self.caster_link, lateralFriction=0.0,
                              spinningFriction=0.0, rollingFriction=0.0)
        client.changeDynamics(self.body_id, -1, lateralFriction=0.3)
        self.synchro = config.drive == "synchro"
        if self.synchro:      # driven kinematically: no wheel friction, no wheel motors
            for link in (-1, *self.wheel_joints):
                client.changeDynamics(self.body_id, link, lateralFriction=0.0)
        # PyBullet places a base by its centre of mass; keep the URDF link frame instead.
        info = client.getDynamicsInfo(self.body_id, -1)
        self._com_in_link = (info[3], info[4])
        self._link_in_com = client.invertTransform(*self._com_in_link)
        self._target = [0.0, 0.0]
        self._current = [0.0, 0.0]
        self._forces = [0.0 if self.synchro else config.wheel_torque] * 2
        self._heading = 0.0                   # synchro: the fixed body heading (radians)
        self._travel = np.zeros(2)            # synchro: commanded travel, body frame (m)
        self._set_motors = client.setJointMotorControlArray

    def set_pose(self, x: float, y: float, yaw: float) -> None:
        """Teleport the robot to a pose on the floor, at rest."""
        quat = self.client.getQuaternionFromEuler([0.0, 0.0, yaw])
        pos, orn = self.client.multiplyTransforms(
            [x, y, self.config.base_height], quat, *self._com_in_link)
        self.client.resetBasePositionAndOrientation(self.body_id, pos, orn)
        self.client.resetBaseVelocity(self.body_id, [0, 0, 0], [0, 0, 0])
        for j in self.wheel_joints:
            self.client.resetJointState(self.body_id, j, 0.0, 0.0)
        self._current = [0.0, 0.0]
        self._heading = float(yaw)
        self._target = [0.0, 0.0]
        self.update_motors(0.0)
        # Refresh the contact cache at the new pose: without this, contacts remembered from
        # before the teleport make the next steps depend on the previous episode.
        self.client.performCollisionDetection()

    def drive(self, v: float, w: float) -> None:
        """Differential drive: command forward speed ``v`` (m/s) and yaw rate ``w``
        (rad/s); the wheel motors ramp towards it in :meth:`update_motors`."""
        if self.synchro:
            raise ValueError("a synchro-drive robot takes drive_planar(vx, vy), not drive(v, w)")
        self._target = list(wheel_speeds(v, w, self.config))

    def drive_planar(self, vx: float, vy: float) -> None:
        """Synchro drive: command the velocity ``(vx, vy)`` (m/s, body frame: x forward,
        y left); the base ramps towards it in :meth:`update_motors`."""
        if not self.synchro:
            raise ValueError("a differential-drive robot takes drive(v, w), not drive_planar")
        self._target = [float(vx), float(vy)]

    def update_motors(self, dt: float) -> None:
        """Move the wheel motor targets (differential) or the base velocity (synchro)
        towards the command by one ramp step of ``dt`` s (called before every physics
        step; plain floats, as it runs 240 times a second)."""
        if self.synchro:
            self._update_synchro(dt)
            return
        if self._current == self._target and dt > 0:
            return
        limit = self.config.wheel_acceleration / self.config.wheel_radius * dt
        self._current = [c + max(-limit, min(limit, t - c))
                         for c, t in zip(self._current, self._target)]
        self._set_motors(self.body_id, self.wheel_joints, p.VELOCITY_CONTROL,
                         targetVelocities=self._current, forces=self._forces)

    def _update_synchro(self, dt: float) -> None:
        (vx, vy), (tx, ty) = self._current, self._target
        gap = math.hypot(tx - vx, ty - vy)
        limit = self.config.wheel_acceleration * dt
        if gap > limit:
            vx, vy = vx + (tx - vx) * limit / gap, vy + (ty - vy) * limit / gap
        else:
            vx, vy = tx, ty
        self._current = [vx, vy]
        self._travel += (vx * dt, vy * dt)
        c, s = math.cos(self._heading), math.sin(self._heading)
        vz = self.client.getBaseVelocity(self.body_id)[0][2]
        self.client.resetBaseVelocity(self.body_id, [c * vx - s * vy, s * vx + c * vy, vz],
                                      [0.0, 0.0, 0.0])

    def encoders(self) -> np.ndarray:
        """The odometry's raw readings: (left, right) wheel joint angles (radians) of the
        differential drive; the synchro drive's commanded travel ``(x, y)`` (metres, body
        frame) since the last teleport."""
        return self._travel.copy() if self.synchro else self.wheel_angles()

    def pose(self) -> np.ndarray:
        """True pose ``(x, y, yaw)`` of the body centre on the floor (float64)."""
        pos, quat = self.client.multiplyTransforms(
            *self.client.getBasePositionAndOrientation(self.body_id), *self._link_in_com)
        yaw = self.client.getEulerFromQuaternion(quat)[2]
        return np.array([pos[0], pos[1], yaw])

    def wheel_angles(self) -> np.ndarray:
        """Encoder readings: (left, right) wheel joint angles in radians."""
        states = self.client.getJointStates(self.body_id, self.wheel_joints)
        return np.array([s[0] for s in states])


class WheelOdometry:
    """Path integration from wheel encoders (dead reckoning), as insects do (Yu & Kim §I).

    Each control step the encoder increments of both wheels are multiplied by
    ``1 + N(0, noise)`` (independent per wheel and step: slip and tyre wear), turned into
    a forward displacement and a heading change by the differential-drive model, and
    integrated with the midpoint rule. The estimate is a pose ``(x, y, yaw)`` in the
    home frame: origin at home, x along the home heading, y to its left.
    """

    def __init__(self, config: RobotConfig, noise: float):
        self.config = config
        self.noise = require_number("odometry_noise", noise, 0, MAX_ODOMETRY_NOISE,
                                    "(relative standard deviation of each wheel increment)")
        self.estimate = np.zeros(3)
        self._last_angles = np.zeros(2)

    def reset(self, initial: np.ndarray, wheel_angles: np.ndarray) -> None:
        """Start integrating from ``initial`` (pose) at the given encoder readings."""
        self.estimate = np.asarray(initial, dtype=np.float64).copy()
        self._last_angles = wheel_angles.copy()

    def update(self, wheel_angles: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        """Integrate the encoder change since the last call; returns the new estimate."""
        delta = (wheel_angles - self._last_angles) * self.config.wheel_radius
        self._last_angles = wheel_angles.copy()
        if self.noise > 0:
            delta = delta * (1.0 + rng.normal(0.0, self.noise, size=2))
        ds = float(delta.mean())
        dyaw = float(delta[1] - delta[0]) / self.config.wheel_separation
        mid = self.estimate[2] + dyaw / 2
        self.estimate = np.array([
            self.estimate[0] + ds * np.cos(mid),
            self.estimate[1] + ds * np.sin(mid),
            wrap_angle(self.estimate[2] + dyaw),
        ])
        return self.estimate


class SynchroOdometry(WheelOdometry):
    """Path integration of the synchro drive: each control step the commanded travel
    since the last call (body frame; :meth:`Robot.encoders`) is scaled by
    ``1 + N(0, noise)`` and added at the estimate's heading, which never changes (the
    body does not rotate)."""

    def update(self, travel: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        delta = travel - self._last_angles
        self._last_angles = travel.copy()
        if self.noise > 0:
            delta = delta * (1.0 + rng.normal(0.0, self.noise))
        c, s = np.cos(self.estimate[2]), np.sin(self.estimate[2])
        self.estimate = self.estimate + (c * delta[0] - s * delta[1],
                                         s * delta[0] + c * delta[1], 0.0)
        return self.estimate


def odometry_for(config: RobotConfig, noise: float) -> WheelOdometry:
    """The odometry of ``config``'s drive, with multiplicative encoder ``noise``."""
    return (SynchroOdometry if config.drive == "synchro" else WheelOdometry)(config, noise)
