"""What a task decides: where an episode starts and ends, what it rewards.

The env core (:mod:`homing_gym.env`) owns the simulator, robot and camera; a
:class:`Task` owns the episode logic. New tasks subclass :class:`Task`; they may add
observation keys through :meth:`Task.extra_spaces` and :meth:`Task.extra_observation`.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from gymnasium import spaces

from homing_gym.scenes.base import Scene, clearance

if TYPE_CHECKING:
    from homing_gym.env import HomingEnv


@dataclass(frozen=True)
class Episode:
    """The poses ``(x, y, yaw)`` (metres, radians CCW) of one episode: the start, and the
    goals to reach in order, ``waypoints`` first and ``home`` last."""

    home: np.ndarray
    start: np.ndarray
    waypoints: tuple[np.ndarray, ...] = ()

    @property
    def goals(self) -> tuple[np.ndarray, ...]:
        return (*self.waypoints, self.home)


class Task(ABC):
    """Episode logic plugged into :class:`~homing_gym.env.HomingEnv`."""

    @abstractmethod
    def sample_episode(self, scene: Scene, rng: np.random.Generator) -> Episode:
        """Draw home and start poses for a new episode."""

    def check_scene(self, scene: Scene) -> None:
        """Raise ``ValueError`` if the task's settings cannot be met in ``scene``."""

    def on_reset(self, env: "HomingEnv") -> None:
        """Called at the end of ``env.reset``, once the robot stands at the start."""

    def command(self, env: "HomingEnv", v: float, w: float,
                stopped: bool) -> tuple[float, float, bool]:
        """The command the robot executes this step, from the agent's validated one
        (normalised forward speed ``v``, yaw rate ``w``, stop flag). Default: the agent's;
        a task may drive the robot itself (long-range homing's outbound phase)."""
        return v, w, stopped

    @abstractmethod
    def step_outcome(self, env: "HomingEnv", collision: bool, stopped: bool) -> tuple[dict, bool, bool]:
        """After a control step: ``(reward terms, terminated, is_success)``."""

    def extra_spaces(self) -> dict[str, spaces.Space]:
        """Observation keys this task adds to the env's observation ``Dict``."""
        return {}

    def extra_observation(self, env: "HomingEnv") -> dict[str, np.ndarray]:
        """Values of the keys of :meth:`extra_spaces` for the current step."""
        return {}

    def extra_info(self, env: "HomingEnv") -> dict:
        """Task-specific entries added to ``info`` at reset and every step."""
        return {}


def sample_free_pose(scene: Scene, rng: np.random.Generator, margin: float,
                     max_tries: int = 1000) -> np.ndarray:
    """A uniformly drawn pose whose floor point has at least ``margin`` metres of clearance."""
    (xmin, ymin), (xmax, ymax) = scene.bounds
    for _ in range(max_tries):
        xy = (float(rng.uniform(xmin, xmax)), float(rng.uniform(ymin, ymax)))
        if clearance(scene, xy) >= margin:
            return np.array([xy[0], xy[1], float(rng.uniform(-np.pi, np.pi))])
    raise RuntimeError(f"scene {scene.name!r}: no pose with {margin} m clearance found in "
                       f"{max_tries} tries")
