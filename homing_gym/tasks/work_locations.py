"""Travel between taught work locations (Shiraishi & Sawasaki §2-§3): the robot stands
at one work location, is told to go to another, follows the taught travel path and must
stop at the target location.

The scene names its work locations and paths in ``metadata["work_locations"]`` and
``metadata["paths"]`` (like ``house``). At the first episode on a path the env teaches it
(:mod:`homing_gym.teaching`): the low-resolution panoramas along the path and the
multiresolution feature image map of the target location, always in the scene *as
taught* (``taught_scene``), so that daily changes made afterwards are seen only during
the run. Taught data is cached per path; it is what the robot recorded on the teaching
day and reaches the agent through the observation (fixed-size arrays, zero-padded, with
counts), never through ``info``.
"""

from __future__ import annotations

import math
from functools import partial

import numpy as np
from gymnasium import spaces

from homing_gym.geometry import wrap_angle
from homing_gym.observations import ObservationKey, constant_key
from homing_gym.paths import connected
from homing_gym.scenes.base import Scene
from homing_gym.tasks.context import TaskContext
from homing_gym.tasks.base import (Episode, check_start_jitter, check_start_off_goal,
                                   checked_start_jitter)
from homing_gym.tasks.goal_reaching import GoalReachingTask, RewardConfig
from homing_gym.teaching import PLACE_SPACING, FeatureMap, teach_path, teach_work_location
from homing_gym.validation import require_number
from homing_gym.vision import low_resolution_shape


#: Most taught places on one path (15 m at 0.47 m) and characteristic points per map
#: (the paper's map of Fig. 2 holds 10).
MAX_PLACES, MAX_POINTS = 32, 10
#: Clearance (m) every start must keep: the robot's radius (0.16 m) and 2 cm.
START_CLEARANCE = 0.18
#: Observation keys this task adds.
TAUGHT_KEYS = ("path_panoramas", "path_count", "map_panorama", "map_templates",
               "map_template_xy", "map_points", "map_count", "map_pose")


class WorkLocationsTask(GoalReachingTask):
    """See the module docstring.

    ``start_location``/``goal_location``: names of work locations, or ``None`` to draw
    the path uniformly among the scene's paths that fit (each joining its two
    locations for a disc of radius ``clearance_margin``, :data:`START_CLEARANCE`). The robot starts at the start
    location, perturbed uniformly by up to ``start_jitter = (metres, radians)`` (where it
    stopped last time). ``panorama_shape`` is the env camera's ``(H, W)``;
    ``teach_levels`` pyramid steps give the low-resolution images; ``spacing`` (m)
    between taught places; ``template_size`` (pixels, odd) and ``max_points`` of the
    feature maps. ``success_radius``/``success_on`` as in :class:`GoalReachingTask`.
    """

    clearance_margin = START_CLEARANCE

    def __init__(self, panorama_shape: tuple[int, int], start_location: str | None = None,
                 goal_location: str | None = None,
                 start_jitter: tuple[float, float] = (0.05, math.radians(5)),
                 teach_levels: int = 2, spacing: float = PLACE_SPACING,
                 template_size: int = 17, max_points: int = MAX_POINTS,
                 success_radius: float = 0.1, success_on: str = "stop",
                 reward: RewardConfig = RewardConfig()):
        start_jitter = checked_start_jitter(start_jitter)
        require_number("teach_levels", teach_levels, 1, 4, "pyramid steps", integer=True)
        require_number("place_spacing", spacing, 0.05, 2.0, "metres")
        if require_number("template_size", template_size, 5, 63, "pixels, odd",
                          integer=True) % 2 == 0:
            raise ValueError(f"template_size must be an odd integer in [5, 63] pixels, "
                             f"got {template_size!r}")
        require_number("max_points", max_points, 2, MAX_POINTS, integer=True)
        if start_location is not None and start_location == goal_location:
            raise ValueError(f"start_location and goal_location are both {start_location!r}; "
                             f"give two different work locations")
        super().__init__(success_radius, success_on, reward)
        self.start_location, self.goal_location = start_location, goal_location
        self.start_jitter = start_jitter
        self.levels = int(teach_levels)
        self.spacing = float(spacing)
        self.template_size = int(template_size)
        self.max_points = int(max_points)
        self.low_shape = low_resolution_shape(tuple(panorama_shape), self.levels)
        #: The scene as it was on the teaching day (set by the env; default: the first
        #: scene the env runs in).
        self.taught_scene: Scene | None = None
        self.path: tuple[str, str] = ("", "")
        self._paths: dict[tuple[str, str], tuple[np.ndarray, np.ndarray]] = {}
        self._maps: dict[str, FeatureMap] = {}
        self._obs: dict[str, np.ndarray] = {}

    # -- scene and episodes -----------------------------------------------------------------
    def _candidate_paths(self, scene: Scene) -> list[tuple[str, str]]:
        return sorted(p for p in scene.metadata["paths"]
                      if self.start_location in (None, p[0])
                      and self.goal_location in (None, p[1]))

    def check_scene(self, scene: Scene) -> None:
        for key in ("work_locations", "paths"):
            if key not in scene.metadata:
                raise ValueError(f"scene {scene.name!r} has no metadata[{key!r}]; work "
                                 f"locations need a scene with taught paths, e.g. 'house'")
        names = sorted(scene.metadata["work_locations"])
        for arg in ("start_location", "goal_location"):
            value = getattr(self, arg)
            if value is not None and value not in names:
                raise ValueError(f"unknown {arg} {value!r}; work locations of scene "
                                 f"{scene.name!r}: {names}")
        if not self._candidate_paths(scene):
            raise ValueError(f"scene {scene.name!r} has no path from {self.start_location!r} "
                             f"to {self.goal_location!r}")
        places = scene.metadata["work_locations"]
        for start, goal in self._candidate_paths(scene):
            check_start_jitter(scene, places[start], self.start_jitter[0], START_CLEARANCE,
                               f"the work location {start!r}")
            check_start_off_goal(places[start], places[goal], self.success_radius,
                                 f"the work locations {start!r} and {goal!r}")
            if not connected(scene, places[start], places[goal], START_CLEARANCE):
                raise ValueError(f"scene {scene.name!r}: no path for a disc of "
                                 f"{START_CLEARANCE} m radius leads from the work location "
                                 f"{start!r} to {goal!r}")
        for key, points in scene.metadata["paths"].items():
            length = float(np.sum(np.linalg.norm(np.diff(points, axis=0), axis=1)))
            if length / self.spacing + len(points) > MAX_PLACES:
                raise ValueError(f"path {key} of {length:.1f} m needs more than {MAX_PLACES} "
                                 f"places at spacing {self.spacing} m; use a larger spacing")
        if self.taught_scene is None:
            self.taught_scene = scene

    def sample_episode(self, scene: Scene, rng: np.random.Generator) -> Episode:
        paths = self._candidate_paths(scene)
        self.path = paths[int(rng.integers(len(paths)))]
        places = scene.metadata["work_locations"]
        d, a = self.start_jitter
        start = np.asarray(places[self.path[0]], np.float64) + np.array(
            [rng.uniform(-d, d), rng.uniform(-d, d), rng.uniform(-a, a)])
        start[2] = wrap_angle(start[2])
        return Episode(home=np.asarray(places[self.path[1]], np.float64), start=start)

    # -- teaching -----------------------------------------------------------------------------
    def on_reset(self, ctx: TaskContext) -> None:
        goal = ctx.scene().metadata["work_locations"][self.path[1]]
        if not np.allclose(ctx.episode().home, goal):
            raise ValueError(f"the goal of WorkLocations-v0 is the work location "
                             f"{self.path[1]!r} at {goal}; reset option 'home' cannot move it")
        if self.path not in self._paths or self.path[1] not in self._maps:
            self._teach(ctx)
        images, _ = self._paths[self.path]
        fmap = self._maps[self.path[1]]
        h, w = self.low_shape
        t, n = self.template_size, len(fmap.points)
        path = np.zeros((MAX_PLACES, h, w), np.uint8)
        path[:len(images)] = images
        templates = np.zeros((MAX_POINTS, t, t), np.uint8)
        templates[:n] = fmap.templates
        xy = np.zeros((MAX_POINTS, 2), np.float32)
        xy[:n] = fmap.template_xy
        points = np.zeros((MAX_POINTS, 3), np.float32)
        points[:n] = fmap.points
        self._obs = {"path_panoramas": path, "path_count": np.int64(len(images)),
                     "map_panorama": fmap.panorama, "map_templates": templates,
                     "map_template_xy": xy, "map_points": points, "map_count": np.int64(n),
                     "map_pose": fmap.pose.astype(np.float32)}
        super().on_reset(ctx)

    def _teach(self, ctx: TaskContext) -> None:
        """Teach the episode's path and its target location in the taught scene, then
        restore the run's world with the robot at the start."""
        run_scene, taught = ctx.scene(), self.taught_scene
        if taught != run_scene:
            ctx.use_world(taught)
        meta = taught.metadata
        if self.path not in self._paths:
            self._paths[self.path] = teach_path(ctx.snapshot, meta["paths"][self.path],
                                                self.levels, self.spacing)
        goal = self.path[1]
        if goal not in self._maps:
            self._maps[goal] = teach_work_location(
                ctx.snapshot, ctx.ray_hit, ctx.robot.camera_height, ctx.camera.vfov,
                meta["work_locations"][goal], meta["feature_points"], self.levels,
                self.template_size, self.max_points)
        if taught != run_scene:
            ctx.use_world(run_scene)
        ctx.place_robot(ctx.episode().start)

    # -- observations -------------------------------------------------------------------------
    def observation_keys(self) -> dict[str, ObservationKey]:
        h, w = self.low_shape
        t = self.template_size
        taught = {
            "path_panoramas": spaces.Box(0, 255, (MAX_PLACES, h, w), np.uint8),
            "path_count": spaces.Discrete(MAX_PLACES + 1),
            "map_panorama": spaces.Box(0, 255, (h, w), np.uint8),
            "map_templates": spaces.Box(0, 255, (MAX_POINTS, t, t), np.uint8),
            "map_template_xy": spaces.Box(0.0, float(max(h, w)), (MAX_POINTS, 2), np.float32),
            "map_points": spaces.Box(-np.inf, np.inf, (MAX_POINTS, 3), np.float32),
            "map_count": spaces.Discrete(MAX_POINTS + 1),
            "map_pose": spaces.Box(-np.inf, np.inf, (3,), np.float32),
        }
        return {key: constant_key(space, partial(self._taught_value, key))
                for key, space in taught.items()}

    def _taught_value(self, key: str) -> np.ndarray:
        value = self._obs[key]
        return value.copy() if isinstance(value, np.ndarray) else value

    def extra_info(self, ctx: TaskContext) -> dict:
        places = self._paths.get(self.path, (None, np.zeros((0, 3))))[1]
        return {"start_location": self.path[0], "goal_location": self.path[1],
                "places": places.copy()}
