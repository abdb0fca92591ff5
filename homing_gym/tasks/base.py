"""What a task decides: where an episode starts and ends, what it rewards.

The env core (:mod:`homing_gym.env`) owns the simulator, robot and camera; a
:class:`Task` owns the episode logic and reaches the env only through a
:class:`~homing_gym.tasks.context.TaskContext`. New tasks subclass :class:`Task`; they may
add observation keys through :meth:`Task.observation_keys`.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from typing import ClassVar

import numpy as np

from homing_gym.observations import ObservationKey
from homing_gym.paths import BODY_RADIUS, RESOLUTION, occupancy, segment_free
from homing_gym.scenes.base import MAX_SIDE, Scene, clearance
from homing_gym.tasks.context import TaskContext
from homing_gym.tasks.episode import Episode
from homing_gym.validation import is_real, require_sequence


class Task(ABC):
    """Episode logic plugged into :class:`~homing_gym.env.HomingEnv`."""

    #: Clear PyBullet's cached contacts when the robot is put at the start (episodes that
    #: may start where the last one ended, see ``LongRangeHomingTask``).
    fresh_contacts: ClassVar[bool] = False
    #: The task commands the robot itself in some phase (unicycle commands from
    #: :meth:`command`), so the synchro drive is not available with it.
    drives_robot: ClassVar[bool] = False
    #: Clearance (m) that the task's starts and goals keep from walls and objects.
    clearance_margin: float = BODY_RADIUS

    @property
    def path_radius(self) -> float:
        """Radius (m) of the disc for which every episode's start and goals, in order, are
        joined by paths (:func:`homing_gym.paths.connected`): the oracle plans and SPL
        measures shortest paths at it. Default: ``clearance_margin``."""
        return self.clearance_margin

    @abstractmethod
    def sample_episode(self, scene: Scene, rng: np.random.Generator) -> Episode:
        """Draw home and start poses for a new episode."""

    def check_scene(self, scene: Scene) -> None:
        """Raise ``ValueError`` if the task's settings cannot be met in ``scene``."""

    def on_reset(self, ctx: TaskContext) -> None:
        """Called at the end of ``env.reset``, once the robot stands at the start."""

    def command(self, ctx: TaskContext, v: float, w: float,
                stopped: bool) -> tuple[float, float, bool]:
        """The command the robot executes this step, from the agent's validated one
        (normalised forward speed ``v``, yaw rate ``w``, stop flag). Default: the agent's;
        a task may drive the robot itself (long-range homing's outbound phase)."""
        return v, w, stopped

    @abstractmethod
    def step_outcome(self, ctx: TaskContext, collision: bool,
                     stopped: bool) -> tuple[dict, bool, bool]:
        """After a control step: ``(reward terms, terminated, is_success)``."""

    def observation_keys(self) -> dict[str, ObservationKey]:
        """Observation keys this task adds to the env's table
        (:mod:`homing_gym.observations`)."""
        return {}

    def extra_info(self, ctx: TaskContext) -> dict:
        """Task-specific entries added to ``info`` at reset and every step."""
        return {}


def check_start_jitter(scene: Scene, point, jitter: float, margin: float, what: str) -> None:
    """``ValueError`` unless every start within ``jitter`` metres (in x and in y) of the
    floor ``point`` keeps ``margin`` metres of clearance: the clearance at ``point`` less
    the square's half diagonal. ``what`` names the point in the message."""
    free = clearance(scene, (point[0], point[1]))
    if free - jitter * math.sqrt(2) < margin:
        fits = max(math.floor((free - margin) / math.sqrt(2) * 1000) / 1000, 0.0)   # mm, down
        raise ValueError(f"start_jitter {jitter!r} m around {what} ({point[0]:.2f}, "
                         f"{point[1]:.2f}) of scene {scene.name!r} could start the robot "
                         f"within {margin} m of a wall or object ({free:.2f} m free there); "
                         f"at most {fits:.3f} m fits")


def checked_start_jitter(value) -> tuple[float, float]:
    """``start_jitter`` as ``(metres, radians)`` floats if it is two numbers, the first
    in ``[0, MAX_SIDE]`` (the scene then bounds it: :func:`check_start_jitter`), the
    second in ``[0, pi]``; else ``ValueError`` naming the value and the ranges."""
    what = (f"(metres, radians): two numbers, metres in [0, {MAX_SIDE:g}] and radians "
            f"in [0, pi]")
    metres, radians = require_sequence("start_jitter", value, 2, what)
    if not (is_real(metres) and is_real(radians) and 0 <= metres <= MAX_SIDE
            and 0 <= radians <= math.pi):
        raise ValueError(f"start_jitter must be {what}, got {value!r}")
    return float(metres), float(radians)


def check_start_off_goal(start, goal, success_radius: float, what: str) -> None:
    """``ValueError`` unless the floor point ``start`` lies farther than
    ``success_radius`` metres from ``goal``: an episode must not begin at its goal.
    ``what`` names the two points in the message."""
    gap = math.dist(start[:2], goal[:2])
    if gap <= success_radius:
        raise ValueError(f"success_radius {success_radius!r} m: {what} are {gap:.3f} m "
                         f"apart, so an episode would begin at its goal; give a "
                         f"success_radius below {gap:.3f} m")


#: Draws over the scene bounds before :func:`sample_free_pose` draws over free cells.
BOUNDS_TRIES = 100


def sample_free_pose(scene: Scene, rng: np.random.Generator, margin: float,
                     max_tries: int = 1000) -> np.ndarray:
    """A pose (x, y, yaw; metres, radians) uniform over the floor points with at least
    ``margin`` metres of clearance: drawn over the scene bounds until one is clear, as
    earlier versions drew it (a seed keeps its episodes), for up to :data:`BOUNDS_TRIES`
    draws; then over the free cells of the grid (:func:`homing_gym.paths.occupancy` at
    ``margin`` and :data:`~homing_gym.paths.RESOLUTION`), so that a mostly blocked world
    costs no more than an open one. ``ValueError`` when no point is that clear."""
    (xmin, ymin), (xmax, ymax) = scene.bounds
    for _ in range(BOUNDS_TRIES):
        xy = (float(rng.uniform(xmin, xmax)), float(rng.uniform(ymin, ymax)))
        if clearance(scene, xy) >= margin:
            return np.array([xy[0], xy[1], float(rng.uniform(-np.pi, np.pi))])
    free, (x0, y0) = occupancy(scene, margin, RESOLUTION)
    cells = np.argwhere(free)
    for _ in range(max_tries if len(cells) else 0):
        (i, j), (dx, dy) = cells[rng.integers(len(cells))], rng.uniform(-0.5, 0.5, 2)
        xy = (float(x0 + (i + dx) * RESOLUTION), float(y0 + (j + dy) * RESOLUTION))
        if clearance(scene, xy) >= margin:
            return np.array([xy[0], xy[1], float(rng.uniform(-np.pi, np.pi))])
    raise ValueError(f"scene {scene.name!r} has no floor point with {margin} m of clearance "
                     f"(none found among {len(cells)} free grid cells of "
                     f"{RESOLUTION} m)")


def random_route(scene: Scene, start, rng: np.random.Generator, length: float,
                 margin: float, legs: tuple[float, float] = (0.8, 2.0),
                 max_turn: float = 2 * math.pi / 3, max_restarts: int = 200) -> np.ndarray:
    """A collision-free polyline ``(K, 2)`` (m) from ``start`` of total length ``length``:
    legs of uniform length in ``legs`` (the last one cut to fit), each turning by up to
    ``max_turn`` radians either way from the last (any direction for the first), every
    point ``margin`` m clear of walls and objects (checked every 5 cm), so that the route's
    end is joined to its start by a path for a disc of radius ``margin``. A leg with no
    clear direction in 30 draws restarts the route; ``ValueError`` naming the scene, the
    length and the margin after ``max_restarts`` routes."""
    for _ in range(max_restarts):
        points = [np.asarray(start[:2], dtype=np.float64)]
        heading = float(rng.uniform(-math.pi, math.pi))
        total = 0.0
        while total < length - 1e-9:
            leg = min(float(rng.uniform(*legs)), length - total)
            for _ in range(30):
                turn = rng.uniform(-math.pi, math.pi) if len(points) == 1 \
                    else rng.uniform(-max_turn, max_turn)
                h = heading + float(turn)
                end = points[-1] + leg * np.array([math.cos(h), math.sin(h)])
                if segment_free(scene, points[-1], end, margin, step=0.05):
                    points.append(end)
                    heading, total = h, total + leg
                    break
            else:
                break
        if total >= length - 1e-9:
            return np.array(points)
    raise ValueError(f"scene {scene.name!r} of size {scene.size} m cannot hold a route of "
                     f"{length} m (legs of {legs[0]}-{legs[1]} m turning by up to "
                     f"{math.degrees(max_turn):.0f} deg) with {margin} m of clearance; use a "
                     f"larger or more open scene or a shorter route")
