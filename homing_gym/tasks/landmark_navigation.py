"""Landmark navigation (Briggs, Scharstein et al. 2000, §4): go and stand in front of the
barcoded landmark whose id is the goal.

The scene must list its landmark panels in ``scene.metadata["landmarks"]`` as
``{id: (x, y, normal)}`` (the centre of the panel's face on the wall, metres, and the
wall normal into the room, radians), and the free rectangles of its floor plan in
``metadata["rooms"]`` (like the ``corridors`` scene). Each episode draws the goal id
among the panels present and a start pose anywhere in the rooms, ``clearance_margin``
metres clear and joined to the goal's standing pose by a path for a disc of that
radius (:func:`homing_gym.paths.connected`).

*In front of* landmark ``g`` (the success test): the robot centre is at most
``max_distance`` metres from the panel centre (horizontally), within ``max_angle`` of
the panel's normal as seen from the panel, and the panel is within ``max_angle`` of the
robot's heading. Defaults 1.2 m and 30 degrees: where the paper's robot stops "in front
of A at a fixed distance" (§4.1) to scan, with room for its servoing error. The goal
pose (for the progress reward and the metrics) is the *standing pose*: ``standoff`` m
out along the normal, facing the panel.
"""

from __future__ import annotations

import math

import numpy as np
from gymnasium import spaces

from homing_gym.geometry import bearing_to, wrap_angle
from homing_gym.observations import ObservationKey, constant_key
from homing_gym.paths import connected
from homing_gym.render.perspective import PerspectiveConfig
from homing_gym.scenes.base import Scene, clearance
from homing_gym.selfsimilar import MAX_ID
from homing_gym.tasks.context import TaskContext
from homing_gym.tasks.base import Episode, Task
from homing_gym.tasks.goal_reaching import SUCCESS_MODES, RewardConfig
from homing_gym.validation import require_positive


#: Length of the one-hot ``goal_id``: every id a barcode can carry.
N_IDS = MAX_ID + 1


def standing_pose(panel: tuple[float, float, float], standoff: float) -> np.ndarray:
    """The pose ``standoff`` m in front of a panel ``(x, y, normal)``, facing it."""
    x, y, normal = panel
    return np.array([x + standoff * math.cos(normal), y + standoff * math.sin(normal),
                     wrap_angle(normal + math.pi)])


class LandmarkNavigationTask(Task):
    """See the module docstring. ``success_on="stop"`` (default) ends the episode when the
    agent stops (a success if it is in front of the goal then); ``"reach"`` as soon as the
    robot is in front of the goal. ``view_size``/``view_hfov_deg``: the optional ``view``
    observation, the forward perspective camera (pixels, degrees)."""

    def __init__(self, max_distance: float = 1.2, max_angle_deg: float = 30.0,
                 standoff: float = 0.8, success_on: str = "stop",
                 reward: RewardConfig = RewardConfig(), clearance_margin: float = 0.25,
                 view_size: tuple[int, int] = (320, 240), view_hfov_deg: float = 60.0):
        require_positive("max_distance", max_distance, "metres")
        require_positive("standoff", standoff, "metres")
        if standoff > max_distance:
            raise ValueError(f"standoff {standoff!r} m must not exceed max_distance "
                             f"{max_distance!r} m")
        if not (0 < max_angle_deg <= 90):
            raise ValueError(f"max_angle_deg must be in (0, 90] degrees, got {max_angle_deg!r}")
        if success_on not in SUCCESS_MODES:
            raise ValueError(f"unknown success_on {success_on!r}; allowed: {SUCCESS_MODES}")
        if len(view_size) != 2:
            raise ValueError(f"view_size must be (width, height) pixels, got {view_size!r}")
        PerspectiveConfig(view_size[0], view_size[1], math.radians(view_hfov_deg))  # checks
        self.max_distance = float(max_distance)
        self.max_angle = math.radians(max_angle_deg)
        self.standoff = float(standoff)
        self.success_on = success_on
        self.reward = RewardConfig.from_value(reward)
        self.clearance_margin = float(clearance_margin)
        self.view_size = (int(view_size[0]), int(view_size[1]))
        self.view_hfov_deg = float(view_hfov_deg)
        self.goal_id = 0
        self._prev_distance = 0.0

    # -- scene and episodes -----------------------------------------------------------------
    def check_scene(self, scene: Scene) -> None:
        for key in ("landmarks", "rooms"):
            if key not in scene.metadata:
                raise ValueError(f"scene {scene.name!r} has no metadata[{key!r}]; landmark "
                                 f"navigation needs a scene with barcoded panels, e.g. "
                                 f"'corridors'")
        bad = [i for i in scene.metadata["landmarks"] if not 0 <= i < N_IDS]
        if bad:
            raise ValueError(f"scene {scene.name!r}: landmark ids {bad} outside [0, {MAX_ID}]")

    def sample_episode(self, scene: Scene, rng: np.random.Generator) -> Episode:
        panels = scene.metadata["landmarks"]
        ids = sorted(panels)
        self.goal_id = int(ids[rng.integers(len(ids))])
        home = standing_pose(panels[self.goal_id], self.standoff)
        rooms = scene.metadata["rooms"]
        areas = np.array([(b[0] - a[0]) * (b[1] - a[1]) for a, b in rooms])
        for _ in range(1000):
            (x0, y0), (x1, y1) = rooms[rng.choice(len(rooms), p=areas / areas.sum())]
            xy = (float(rng.uniform(x0, x1)), float(rng.uniform(y0, y1)))
            start = np.array([*xy, float(rng.uniform(-math.pi, math.pi))])
            if (clearance(scene, xy) >= self.clearance_margin
                    and not self.in_front(scene, start, self.goal_id)
                    and connected(scene, xy, home, self.clearance_margin)):
                return Episode(home=home, start=start)
        raise ValueError(f"scene {scene.name!r}: no start pose in its rooms with "
                         f"{self.clearance_margin} m of clearance from which a disc of that "
                         f"radius can reach the standing pose of landmark {self.goal_id} "
                         f"({home[0]:.2f}, {home[1]:.2f}) (1000 tries)")

    def in_front(self, scene: Scene, pose, landmark_id: int) -> bool:
        """Whether ``pose`` stands in front of landmark ``landmark_id`` (module docstring)."""
        x, y, normal = scene.metadata["landmarks"][landmark_id]
        dx, dy = pose[0] - x, pose[1] - y
        if math.hypot(dx, dy) > self.max_distance:
            return False
        off_normal = abs(wrap_angle(math.atan2(dy, dx) - normal))
        return off_normal <= self.max_angle and abs(bearing_to(pose, (x, y))) <= self.max_angle

    # -- steps ----------------------------------------------------------------------------------
    def on_reset(self, ctx: TaskContext) -> None:
        self._prev_distance = ctx.distance_to_goal()

    def step_outcome(self, ctx: TaskContext, collision: bool, stopped: bool):
        distance = ctx.distance_to_goal()
        success = self.in_front(ctx.scene(), ctx.pose(), self.goal_id)
        terminated = stopped if self.success_on == "stop" else success
        success = success and terminated
        rewards = {
            "progress": self.reward.progress * (self._prev_distance - distance),
            "success": self.reward.success if success else 0.0,
            "collision": -self.reward.collision if collision else 0.0,
            "time": -self.reward.time,
            "wrong_stop": -self.reward.wrong_stop if terminated and not success else 0.0,
        }
        self._prev_distance = distance
        return rewards, terminated, success

    # -- observations ---------------------------------------------------------------------------
    def observation_keys(self) -> dict[str, ObservationKey]:
        w, h = self.view_size
        return {"goal_id": constant_key(spaces.Box(0.0, 1.0, (N_IDS,), np.float32),
                                        self._goal_one_hot),
                "view": ObservationKey(
                    lambda config: spaces.Box(0, 255, (h, w, 3), np.uint8),
                    lambda sight: sight.view(self.view_size, self.view_hfov_deg))}

    def _goal_one_hot(self) -> np.ndarray:
        one_hot = np.zeros(N_IDS, np.float32)
        one_hot[self.goal_id] = 1.0
        return one_hot

    def extra_info(self, ctx: TaskContext) -> dict:
        return {"goal_id": self.goal_id}
