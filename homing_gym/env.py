"""The env core: simulator + robot + panoramic camera + a task, behind the Gymnasium API.

:class:`HomingEnv` knows nothing about any particular task or scene: the scene comes from
the scene registry (:mod:`homing_gym.scenes`), the episode logic from a
:class:`~homing_gym.tasks.Task`, the observation keys from :data:`OBSERVATION_KEYS` and
the task's own keys. Registered envs (``homing_gym/LocalHoming-v0``, ...) are thin
subclasses in :mod:`homing_gym.envs` that choose the task and carry the env card.
"""

from __future__ import annotations

import dataclasses
import inspect
import math
from typing import Any, Protocol

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from homing_gym.actions import DiscreteAction
from homing_gym.config import EnvConfig, env_config
from homing_gym.geometry import finite_pose, to_frame
from homing_gym.observations import (CORE_KEYS, PANORAMA_KEYS, ObservationKey, Sight,
                                     goal_step_key)
from homing_gym.render.panorama import (Lighting, PanoramaCamera, random_lighting,
                                        world_lighting)
from homing_gym.paths import occupancy
from homing_gym.render.perspective import PerspectiveConfig, render_perspective
from homing_gym.render.raycast import RayCaster
from homing_gym.sim.robot import odometry_for
from homing_gym.scenes import scene_factory
from homing_gym.scenes.base import Scene, clearance
from homing_gym.sim.simulator import Simulator
from homing_gym.tasks.base import Task
from homing_gym.tasks.context import TaskContext
from homing_gym.tasks.episode import Episode
from homing_gym.render.topdown import compose_frame, draw_topdown

#: Observation keys the env core provides (tasks may add more): see
#: :mod:`homing_gym.observations`.
OBSERVATION_KEYS = (*CORE_KEYS, "goal_step")
#: Grid (metres) on which a new world is checked for room for the robot.
ROOM_RESOLUTION = 0.05


def simulation_settings(env_kwargs: dict) -> dict:
    """The renderer and physics sub-steps an env made with ``env_kwargs`` runs with (the
    given ones, else the defaults), and its motion model unless PyBullet's: what result
    files record beside the policy."""
    settings = {"renderer": env_kwargs.get("renderer", EnvConfig.renderer),
                "physics_substeps": env_kwargs.get("physics_substeps",
                                                   EnvConfig.physics_substeps)}
    if env_kwargs.get("motion", EnvConfig.motion) != EnvConfig.motion:
        settings["motion"] = env_kwargs["motion"]     # named in every row that uses it
    return settings


def _check_room(scene: Scene, radius: float) -> None:
    """Refuse a world in which the robot (a disc of ``radius`` metres) fits nowhere."""
    if not occupancy(scene, radius, ROOM_RESOLUTION)[0].any():
        raise ValueError(f"scene {scene.name!r} has no free space for the robot (a disc of "
                         f"radius {radius} m) within its bounds {scene.bounds!r} at the "
                         f"robot's height ({scene.height_band[0]}-{scene.height_band[1]} m)")


#: Spawn key that sets a seed's world stream apart from its episode stream.
WORLD_STREAM = 0x776F726C64


def world_seeds(rng: np.random.Generator) -> np.random.SeedSequence:
    """The world stream of an episode generator seeded by ``reset(seed=...)``: world ``k``
    of the unseeded resets that follow is built from its ``k``-th child, so the worlds
    to come are known ahead (and can be built in the background) whatever the episodes
    draw."""
    parent = rng.bit_generator.seed_seq
    return np.random.SeedSequence(parent.entropy, spawn_key=(*parent.spawn_key, WORLD_STREAM),
                                  pool_size=parent.pool_size)


class WorldSource(Protocol):
    """Builds a procedural scene's worlds ahead of need (:mod:`homing_gym.vector.worlds`)."""

    def world(self, seeds: np.random.SeedSequence) -> tuple[Scene, RayCaster | None] | None:
        """The world built from ``seeds`` (and its ray caster), or ``None`` to build it
        here."""

    def ahead(self, stream: np.random.SeedSequence) -> None:
        """Start building the next world of ``stream`` (its next child)."""


def check_env_kwargs(env_class: type, kwargs: dict) -> None:
    """``ValueError`` naming the keyword arguments in ``kwargs`` that neither
    ``env_class.__init__`` nor :class:`HomingEnv` (``scene`` and the fields of
    :class:`~homing_gym.config.EnvConfig`) takes, and listing those they do
    (instead of Python's ``TypeError``, which names one and lists none)."""
    names = {f.name for f in dataclasses.fields(EnvConfig)} | {"scene"}
    names.update(name for name, param in inspect.signature(env_class.__init__).parameters.items()
                 if param.kind in (param.POSITIONAL_OR_KEYWORD, param.KEYWORD_ONLY))
    allowed = sorted(names - {"self", "task"})
    unknown = sorted(set(kwargs) - set(allowed))
    if unknown:
        raise ValueError(f"{env_class.__name__} got unknown keyword arguments {unknown}; "
                         f"allowed: {allowed}")


class HomingEnv(gym.Env):
    """A differential-drive robot with a panoramic camera in a PyBullet scene.

    See :class:`homing_gym.envs.LocalHomingEnv` for the full description of spaces and
    arguments; ``task`` is a :class:`~homing_gym.tasks.Task` instance, ``settings`` the
    fields of :class:`~homing_gym.config.EnvConfig` (its defaults where left out).
    """

    metadata = {"render_modes": ["human", "rgb_array"], "render_fps": 10}

    def __init__(self, task: Task, scene: str | Scene = "arena", **settings):
        config = env_config(settings)
        table: dict[str, ObservationKey] = {**CORE_KEYS,
                                            "goal_step": goal_step_key(config.goal_step_length),
                                            **task.observation_keys()}
        allowed = tuple(table)
        keys = config.obs_keys if isinstance(config.obs_keys, tuple) else ()
        if (not keys or any(k not in allowed for k in keys)
                or len(set(keys)) != len(keys)):
            raise ValueError(f"bad obs_keys {config.obs_keys!r}: give a list or tuple of "
                             f"distinct keys from {allowed}")
        if config.drive == "synchro" and task.drives_robot:
            raise ValueError(f"drive='synchro' is not available in {type(task).__name__}: "
                             f"the task drives the robot itself (unicycle commands)")

        #: The env's settings (:class:`~homing_gym.config.EnvConfig`).
        self.config = config
        self.render_mode = config.render_mode
        self.task = task
        self.obs_keys = config.obs_keys
        self.action_type = config.action_type
        self.control_period = config.control_period
        self.physics_substeps = config.physics_substeps
        self.stop_threshold = config.stop_threshold
        self.lighting_change = config.lighting_change
        self.episodes_per_world = config.episodes_per_world
        self._world_episodes_left = 0
        #: Where the worlds of a procedural scene's unseeded resets come from: built here
        #: (None) or ahead of need by a :class:`WorldSource` (the native vector env's).
        self.world_source: WorldSource | None = None
        self._world_seeds: np.random.SeedSequence | None = None
        self.goal_step_length = config.goal_step_length
        #: The run's lighting (the world's, or changed: ``lighting_change``) and the
        #: world's own, under which snapshots are taken (None: the renderers' default).
        self._lighting: Lighting | None = None
        self._world_lighting: Lighting | None = None
        #: The ``scene`` argument (a name, ``"mesh:PATH"``, a :class:`Scene`...).
        self.scene_spec = scene
        self._scene_factory = scene_factory(scene)
        self.scene = self._scene_factory.build(np.random.default_rng(0))
        self.robot_config = config.robot(self.scene.appearance.camera_height)
        self.odometry = odometry_for(self.robot_config, config.odometry_noise)
        self.odometry_origin = config.odometry_origin
        _check_room(self.scene, self.robot_config.body_radius)
        task.check_scene(self.scene)
        self.sim = Simulator(self.scene, gui=self.render_mode == "human",
                             time_step=self.control_period / self.physics_substeps,
                             robot_config=self.robot_config, renderer=config.renderer,
                             sky_color=config.sky_color, shadows=config.shadows,
                             motion=config.motion)
        self.camera = PanoramaCamera(
            config.camera(), self.robot_config.camera_height, renderer=self.sim.renderer,
            caster=(lambda: self.sim.caster) if self.sim.caster is not None else None,
            vertices=self.sim.world_vertices if self.sim.caster is None else None)

        self._table = {k: table[k] for k in self.obs_keys}
        self.observation_space = spaces.Dict(
            {k: entry.space(self.camera.config) for k, entry in self._table.items()})
        if config.action_type == "discrete":
            self.action_space = spaces.Discrete(len(DiscreteAction))
        else:
            self.action_space = spaces.Box(-1.0, 1.0, (2,), np.float32)

        self.episode: Episode | None = None
        self.pose = np.zeros(3)
        self.trajectory: list[tuple[float, float]] = []
        self.collisions = 0
        self._panorama: np.ndarray | None = None   # rendered on first use after a move
        self._last_obs: dict[str, np.ndarray] = {}
        self._previous_panorama: np.ndarray | None = None   # the last observation's view
        self._skip_images = False
        self.goal_index = 0
        self._goal_views: list[dict[str, np.ndarray] | None] = []
        self._goal_obs: dict[str, np.ndarray] = {}
        self._start_pose = np.zeros(3)
        self._task_context = TaskContext(
            pose=lambda: self.pose, distance_to_goal=lambda: self.distance_to_goal,
            goal_index=lambda: self.goal_index, episode=lambda: self.episode,
            scene=lambda: self.scene, rng=lambda: self.np_random, obs_keys=self.obs_keys,
            robot=self.robot_config, camera=self.camera.config,
            place_robot=self._place_robot, snapshot=self._snapshot_panorama,
            ray_hit=self.sim.ray_hit, use_world=self.sim.reset_world,
            advance_goal=self.advance_goal)

    # -- helpers --------------------------------------------------------------------------
    @property
    def draws_worlds(self) -> bool:
        """Whether the scene is procedural: a new world is drawn on every seeded reset
        (and every ``episodes_per_world`` unseeded ones), so a scene name does not name
        one world."""
        return self._scene_factory.randomised

    @property
    def panorama(self) -> np.ndarray:
        """The panorama at the robot's current pose, rendered when first read after a
        move (observation keys ``panorama``, ``omni``, ``signature`` and the ``rgb_array``
        picture read it; an agent that observes only other keys costs no panorama)."""
        if self._panorama is None:
            self._panorama = self.camera.render(self.sim.client, self.pose, self._lighting)
        return self._panorama

    def skip_next_images(self) -> None:
        """Harness hint for one step: the agent will not read the next observation (a
        scripted controller in the middle of a move, see
        :meth:`homing_baselines.base.Controller.needs_next_observation`), so the next
        :meth:`step` renders no camera image and returns the previous observation with
        fresh ``odometry``. Episodes, rewards and info are unchanged."""
        self._skip_images = True

    def render_panorama(self, pose) -> np.ndarray:
        """Panorama (uint8 HWC) the robot's camera would see at ``pose`` in the current
        world and the episode's lighting, rendered as is (the robot body stays where it is)."""
        return self.camera.render(self.sim.client, finite_pose(pose), self._lighting)

    def render_view(self, pose=None, size: tuple[int, int] = (640, 480),
                    hfov_deg: float = 60.0) -> np.ndarray:
        """An ordinary perspective view (uint8 ``(height, width, 3)``) from the robot's
        camera at ``pose`` (default: the robot's current pose; ``(x, y, yaw)`` in metres
        and radians), ``size = (width, height)`` pixels and ``hfov_deg`` degrees of
        horizontal field of view, under the episode's lighting. The world and the
        episode are left untouched (see :mod:`homing_gym.render.perspective`)."""
        config = PerspectiveConfig(width=size[0], height=size[1], hfov=math.radians(hfov_deg))
        pose = self.pose if pose is None else finite_pose(pose)
        return render_perspective(self.sim.client, pose, self.robot_config.camera_height, config,
                                  self.sim.renderer, self._lighting, self.sim.caster)

    @property
    def goal_pose(self) -> np.ndarray:
        """The pose of the current goal (home, or the current waypoint of a route)."""
        return self.episode.goals[self.goal_index]

    @property
    def distance_to_goal(self) -> float:
        """Distance (metres) between the robot centre and the current goal position."""
        goal = self.goal_pose
        return float(math.hypot(self.pose[0] - goal[0], self.pose[1] - goal[1]))

    def advance_goal(self) -> None:
        """Make the next goal of the episode current (tasks with routes call this)."""
        if self.goal_index + 1 >= len(self.episode.goals):
            raise RuntimeError("the episode has no further goal")
        self.goal_index += 1
        if self._goal_views[self.goal_index] is None:      # see reset: taken when needed
            self._goal_views[self.goal_index] = self._snapshot(self.goal_pose, move_robot=False)
        self._goal_obs = self._goal_views[self.goal_index]

    def _snapshot_panorama(self, pose, move_robot: bool = True) -> np.ndarray:
        """The panorama taken at ``pose`` under snapshot-time lighting, with the robot
        standing there (it stays there) when ``move_robot``."""
        if move_robot:
            self.sim.robot.set_pose(*pose)
        return self.camera.render(self.sim.client, pose, self._world_lighting)

    def _use_appearance(self) -> None:
        """Take the current world's light and camera height
        (:class:`~homing_gym.scenes.appearance.Appearance`; the env's ``camera_height``
        wins over the world's; a pair of them draws the episode's from ``np_random``)."""
        self._world_lighting = world_lighting(self.scene.appearance)
        robot = self.config.robot(self.scene.appearance.camera_height, self.np_random)
        if robot != self.robot_config:
            self.robot_config = robot
            self.camera.camera_height = robot.camera_height
            self._task_context = dataclasses.replace(self._task_context, robot=robot)

    def _place_robot(self, pose, clear_contacts: bool = False) -> None:
        """Teleport the robot to ``pose`` and restart odometry there: at zero
        (``odometry_origin="start"``) or at the pose in home's frame (``"home"``)."""
        self.sim.place_robot(pose, clear_contacts)
        self.pose = self.sim.robot.pose()
        origin = self.episode.home if self.odometry_origin == "home" else self.pose
        self.odometry.reset(to_frame(origin, self.pose), self.sim.robot.encoders())

    def _goal_sight(self, pose: np.ndarray, move_robot: bool = True) -> Sight:
        """The snapshot of a goal: its panorama is taken now, with the robot standing at
        ``pose`` when ``move_robot``; ``panorama_ahead(d)`` renders ``d`` metres straight
        ahead of it."""
        def ahead(d: float) -> np.ndarray:
            return self._snapshot_panorama(np.array(
                [pose[0] + d * math.cos(pose[2]), pose[1] + d * math.sin(pose[2]), pose[2]]),
                move_robot)

        panorama = self._snapshot_panorama(pose, move_robot)
        return Sight(self.camera, lambda: panorama, ahead=ahead)

    def _snapshot(self, pose: np.ndarray, move_robot: bool = True) -> dict[str, np.ndarray]:
        """The goal observation keys of a snapshot taken at ``pose`` (``goal`` always:
        the ``rgb_array`` picture shows it)."""
        sight = self._goal_sight(pose, move_robot)
        views = {"goal": sight.panorama}
        views.update({k: entry.produce(sight) for k, entry in self._table.items()
                      if entry.goal and k != "goal"})
        return views

    def _command(self, action) -> tuple[float, float, bool]:
        """Validated action -> (forward, yaw) in normalised units and the stop flag.
        Real numbers only: booleans, complex numbers, strings and ``None`` are refused."""
        if (self.action_type != "discrete" and type(action) is np.ndarray
                and action.shape == (2,) and action.dtype.kind == "f"):   # the usual case, fast
            v, w = float(action[0]), float(action[1])
            if not (math.isfinite(v) and math.isfinite(w)):
                raise ValueError(f"action {action!r} contains NaN or infinity")
            v, w = min(max(v, -1.0), 1.0), min(max(w, -1.0), 1.0)
            return v, w, abs(v) < self.stop_threshold and abs(w) < self.stop_threshold
        a = np.asarray(action, dtype=object if action is None else None)
        mixed_bools = isinstance(action, (list, tuple)) and any(
            isinstance(x, (bool, np.bool_)) for x in action)
        real = a.dtype.kind in "iuf" and not mixed_bools
        if self.action_type == "discrete":
            if not (real and a.ndim == 0 and np.isfinite(a) and float(a).is_integer()
                    and int(a) in iter(DiscreteAction)):
                names = ", ".join(f"{d.value} {d.name.lower()}" for d in DiscreteAction)
                raise ValueError(f"discrete action {action!r} is not one of {names}")
            chosen = DiscreteAction(int(a))
            v, w = chosen.command
            return v, w, chosen is DiscreteAction.STOP
        if not real:
            raise ValueError(f"action {action!r} must be two real numbers (forward, yaw rate) "
                             f"in [-1, 1]; got {a.dtype.name} values")
        if a.shape != (2,):
            raise ValueError(f"action {action!r} must have shape (2,) = (forward, yaw rate)")
        if not np.all(np.isfinite(a)):
            raise ValueError(f"action {action!r} contains NaN or infinity")
        v, w = np.clip(a.astype(np.float64), -1.0, 1.0)
        stop = abs(v) < self.stop_threshold and abs(w) < self.stop_threshold
        return float(v), float(w), bool(stop)

    def observation(self, skip_images: bool = False) -> dict[str, np.ndarray]:
        """The observation of the current step from the table; with ``skip_images`` (as
        :meth:`advance` returns it after :meth:`skip_next_images`), the rendered keys
        repeat their last value."""
        sight = Sight(self.camera, lambda: self.panorama, odometry=lambda: self.odometry.estimate,
                      view=lambda size, hfov: self.render_view(size=size, hfov_deg=hfov),
                      previous=lambda: self._previous_panorama)
        obs: dict[str, np.ndarray] = {}
        for key, entry in self._table.items():
            if entry.goal:
                obs[key] = self._goal_obs[key].copy()
            elif skip_images and entry.rendered and key in self._last_obs:
                obs[key] = self._last_obs[key].copy()
            else:
                obs[key] = entry.produce(sight)
        if "previous" in self._table and not (skip_images and self._last_obs):
            self._previous_panorama = self.panorama.copy()     # the next step's "previous"
        self._last_obs = obs
        return obs

    def _episode_with_options(self, episode: Episode, options: dict) -> Episode:
        """Apply ``reset(options={"home": pose, "start": pose})`` overrides (poses
        ``(x, y, yaw)`` in metres and radians, inside the scene bounds; the start with
        room for the robot's body, the home off walls and objects)."""
        if not isinstance(options, dict):
            raise ValueError(f"reset options must be a dict with keys 'home' and/or 'start', "
                             f"got {options!r}")
        unknown = sorted(set(options) - {"home", "start"})
        if unknown:
            raise ValueError(f"unknown reset options {unknown}; allowed: ['home', 'start']")
        poses = {"home": episode.home, "start": episode.start}
        (xmin, ymin), (xmax, ymax) = self.scene.bounds
        for key, value in options.items():
            try:
                pose = finite_pose(value)
                inside = xmin <= pose[0] <= xmax and ymin <= pose[1] <= ymax
            except ValueError:
                inside = False                        # refused just below, with its name
            if not inside:
                raise ValueError(f"reset option {key}={value!r} must be a finite pose "
                                 f"(x, y, yaw) with x in [{xmin}, {xmax}], y in [{ymin}, {ymax}]")
            # the robot stands at the start; the home only needs to be in free space
            need = self.robot_config.body_radius if key == "start" else 0.0
            free = clearance(self.scene, (pose[0], pose[1]))
            if free <= need:
                raise ValueError(f"reset option {key}={value!r} lies in a wall or object"
                                 + (f" for the robot (radius {need} m)" if need else "")
                                 + f": {max(free, 0.0):.3f} m free there")
            poses[key] = pose
        return Episode(home=poses["home"], start=poses["start"], waypoints=episode.waypoints)

    def _info(self, collision: bool = False, success: bool = False,
              rewards: dict[str, float] | None = None) -> dict[str, Any]:
        return {
            "pose": self.pose.copy(),
            "goal_pose": self.goal_pose.copy(),
            "home_pose": np.array(self.episode.home, dtype=np.float64),
            "start_pose": self._start_pose.copy(),
            "distance_to_goal": self.distance_to_goal,
            "is_success": bool(success),
            "collision": bool(collision),
            "collisions": self.collisions,
            "rewards": rewards or {},
            **self.task.extra_info(self._task_context),
        }

    # -- Gymnasium API --------------------------------------------------------------------
    def reset(self, *, seed: int | None = None, options: dict | None = None):
        self._check_open()
        if isinstance(seed, (bool, np.bool_)):     # an int to Python, not a seed
            raise ValueError(f"seed must be an integer >= 0 or None, got {seed!r}")
        super().reset(seed=seed)
        if seed is not None or self._world_seeds is None:
            self._world_seeds = world_seeds(self.np_random)
        # a randomised scene draws a new world on a seeded reset and every
        # episodes_per_world unseeded ones (building a procedural world costs tens of ms):
        # a seeded reset's from the seed, the others' from the seed's world stream
        caster = None
        if self._scene_factory.randomised and (seed is not None
                                               or self._world_episodes_left <= 0):
            if seed is not None:
                self.scene = self._scene_factory.build(self.np_random)
            else:
                seeds = self._world_seeds.spawn(1)[0]
                built = self.world_source.world(seeds) if self.world_source else None
                self.scene, caster = built or (
                    self._scene_factory.build(np.random.default_rng(seeds)), None)
            self._world_episodes_left = self.episodes_per_world
        self._world_episodes_left -= 1
        self.sim.reset_world(self.scene, caster)
        self._use_appearance()
        if self.world_source is not None and self._scene_factory.randomised:
            self.world_source.ahead(self._world_seeds)
        try:
            episode = self.task.sample_episode(self.scene, self.np_random)
        except ValueError as error:          # say which world: a procedural one is its seed's
            raise ValueError(f"{error} (world drawn by reset(seed={seed!r}))"
                             if self.draws_worlds else str(error)) from error
        self.episode = self._episode_with_options(episode, options or {})
        # the ray caster never sees the robot's body, so it takes the snapshot of each
        # later goal (a route's targets) when that goal becomes current, without moving
        # the robot: a route of thousands of targets resets at the cost of one
        lazy = self.sim.caster is not None
        self._goal_views = [None if k and lazy else self._snapshot(goal)
                            for k, goal in enumerate(self.episode.goals)]
        self.goal_index = 0
        self._goal_obs = self._goal_views[0]
        self._lighting = (random_lighting(self.np_random, self.lighting_change)
                          if self.lighting_change > 0 else self._world_lighting)
        self._place_robot(self.episode.start, self.task.fresh_contacts)
        self._start_pose = self.pose.copy()
        self._panorama = None
        self._skip_images = False
        self._last_obs = {}
        self._previous_panorama = None
        self.trajectory = [(float(self.pose[0]), float(self.pose[1]))]
        self.collisions = 0
        self.task.on_reset(self._task_context)
        return self.observation(), self._info()

    def step(self, action):
        reward, terminated, info, skip_images = self.advance(action)
        return self.observation(skip_images), reward, terminated, False, info

    def advance(self, action) -> tuple[float, bool, dict[str, Any], bool]:
        """:meth:`step` without its observation: the robot moves, the task scores the
        move; ``(reward, terminated, info, skip_images)``. The observation follows from
        :meth:`observation` (:mod:`homing_gym.vector` renders the panoramas of many
        envs in threads between the two)."""
        self._check_open()
        if self.episode is None:
            raise RuntimeError("call reset() before step()")
        v, w, stopped = self.task.command(self._task_context, *self._command(action))
        robot = self.sim.robot
        if robot.synchro:     # (v, w) read as the body-frame velocity, speed at most max_speed
            scale = self.robot_config.max_speed / max(1.0, math.hypot(v, w))
            robot.drive_planar(v * scale, w * scale)
        else:
            robot.drive(v * self.robot_config.max_speed, w * self.robot_config.max_yaw_rate)
        collision = self.sim.step(self.physics_substeps)
        self.pose = robot.pose()
        if "odometry" in self.obs_keys:
            self.odometry.update(robot.encoders(), self.np_random)
        self._panorama = None
        skip_images, self._skip_images = self._skip_images, False
        self.trajectory.append((float(self.pose[0]), float(self.pose[1])))
        self.collisions += int(collision)
        rewards, terminated, success = self.task.step_outcome(self._task_context, collision, stopped)
        reward = float(sum(rewards.values()))
        if self.render_mode == "human":
            self.render()
        return reward, bool(terminated), self._info(collision, success, rewards), skip_images

    @property
    def reads_panorama(self) -> bool:
        """Whether the observation reads the current panorama (keys of
        :data:`~homing_gym.observations.PANORAMA_KEYS`) and the ray caster draws it: then
        :meth:`render_panorama_now` may run in another thread (the caster's kernels
        release the GIL), one env at a time."""
        return self.sim.caster is not None and any(k in PANORAMA_KEYS for k in self.obs_keys)

    def render_panorama_now(self) -> None:
        """Render the current panorama now (if not yet rendered since the last move), so
        that the next observation reads it."""
        if self._panorama is None:
            self._panorama = self.camera.render(self.sim.client, self.pose, self._lighting)

    def render(self):
        self._check_open()
        if self.render_mode == "rgb_array":
            return self.render_frame()
        if self.render_mode == "human" and self.episode is not None:
            self.sim.client.resetDebugVisualizerCamera(
                cameraDistance=2.5, cameraYaw=math.degrees(self.pose[2]) - 90,
                cameraPitch=-55, cameraTargetPosition=[self.pose[0], self.pose[1], 0])
        return None

    def render_frame(self) -> np.ndarray:
        """The ``rgb_array`` picture: top-down map beside current and goal panoramas."""
        if self.episode is None:
            raise RuntimeError("call reset() before render()")
        top = draw_topdown(self.scene, self.pose, self.goal_pose, self.trajectory,
                           robot_radius=self.robot_config.body_radius,
                           success_radius=getattr(self.task, "success_radius", None),
                           waypoints=self.episode.goals)
        caption = f"(d = {self.distance_to_goal:.2f} m)"
        return compose_frame(top, self.panorama, self._goal_obs["goal"], caption)

    def close(self):
        if hasattr(self, "sim"):
            self.sim.close()

    def __reduce_ex__(self, protocol):
        # a copy would share the PyBullet client (and disconnect it when collected)
        raise TypeError(f"{type(self).__name__} cannot be copied or pickled: it holds a live "
                        f"PyBullet world; make another with gym.make(env.spec), and give "
                        f"vector envs functions that make envs")

    def _check_open(self) -> None:
        if hasattr(self, "sim") and not self.sim.connected:
            raise gym.error.ClosedEnvironmentError(
                "this env was closed (its PyBullet world is gone); make a new one")
