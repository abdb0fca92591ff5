"""What a task may read and do: the narrow contract between the env core and its tasks.

The env builds one :class:`TaskContext` and hands it to every :class:`~homing_gym.tasks.Task`
hook; a task never sees the env, the simulator client or the camera. Reads are calls
(``ctx.pose()``) because they change as the episode runs. Poses are ``(x, y, yaw)`` in
metres and radians (counter-clockwise from world +x).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from homing_gym.render.panorama import CameraConfig
from homing_gym.sim.robot import RobotConfig
from homing_gym.scenes.base import Scene
from homing_gym.tasks.episode import Episode


@dataclass(frozen=True)
class TaskContext:
    """The env's services for a task.

    Reads: ``pose()`` the robot's true pose; ``distance_to_goal()`` (metres, robot centre
    to the current goal); ``goal_index()`` into ``episode().goals``; ``scene()`` the
    world of this episode; ``rng()`` the env's generator seeded by ``reset(seed=...)``;
    ``obs_keys`` the observation keys the agent asked for; ``robot`` and ``camera`` the
    robot and camera settings.

    Actions: ``place_robot(pose, clear_contacts=False)`` teleports the robot, restarts
    odometry there (in the frame of home) and, if asked, clears PyBullet's cached contacts;
    ``snapshot(pose)`` is the panorama taken with the robot standing at ``pose`` under
    snapshot-time lighting (it leaves the robot there: place it back afterwards);
    ``ray_hit(start, end)`` is the first point a straight ray from ``start`` to ``end``
    (3-D, metres) hits, or ``None``; ``use_world(scene)`` rebuilds the simulated world
    as ``scene`` (teaching in the world as it was on the teaching day);
    ``advance_goal()`` makes the episode's next goal current.
    """

    pose: Callable[[], np.ndarray]
    distance_to_goal: Callable[[], float]
    goal_index: Callable[[], int]
    episode: Callable[[], Episode]
    scene: Callable[[], Scene]
    rng: Callable[[], np.random.Generator]
    obs_keys: tuple[str, ...]
    robot: RobotConfig
    camera: CameraConfig
    place_robot: Callable[..., None]
    snapshot: Callable[[np.ndarray], np.ndarray]
    ray_hit: Callable[[Sequence[float], Sequence[float]], np.ndarray | None]
    use_world: Callable[[Scene], None]
    advance_goal: Callable[[], None]
