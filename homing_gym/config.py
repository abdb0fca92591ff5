"""The env core's arguments: :class:`EnvConfig`, one frozen dataclass validated in one place.

Each field carries its row of the *field table* (:func:`field_table`): the allowed values
(a :class:`Range`, :class:`Choices`, :class:`Positive` or a :class:`Rule` checked in
:meth:`EnvConfig.__post_init__`), the unit and a one-line meaning. The defaults are the
fields' defaults; the range checks run from the same table, and the env cards'
argument tables (:mod:`homing_gym.envcard`) are written from it, so what the docs say
cannot drift from what the code does. A task's own arguments (``start_distance``,
``success_on``, ...) are the env classes' (:mod:`homing_gym.envs`).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np

from homing_gym.render.panorama import N_VIEWS, PANORAMA_SHAPES, RENDERERS, CameraConfig
from homing_gym.scenes.appearance import CAMERA_HEIGHT_RANGE
from homing_gym.sim.robot import DRIVES, MAX_ODOMETRY_NOISE, RobotConfig
from homing_gym.sim.simulator import gui_unavailable
from homing_gym.validation import (interval, is_real, require_number, require_positive,
                                   require_sequence)

RENDER_MODES = ("human", "rgb_array")
#: How the robot moves (``motion``): PyBullet's physics or a kinematic unicycle.
MOTIONS = ("pybullet", "kinematic")
ACTION_TYPES = ("continuous", "discrete")
#: Where ``odometry`` starts: zero in the start pose's frame (path integration from where
#: the robot was put), or the start pose in home's frame (a privileged homing vector).
ODOMETRY_ORIGINS = ("start", "home")
#: Bounds of the simulation settings: physics sub-steps per control period, the control
#: period (seconds) and the physics step (seconds; longer steps let the robot pass
#: through walls, shorter ones only cost time).
MAX_SUBSTEPS, MAX_CONTROL_PERIOD = 1000, 2.0
MIN_TIME_STEP, MAX_TIME_STEP = 1 / 2000, 1 / 60
#: Most episodes in one procedural world (``episodes_per_world``): a bound for a counter,
#: far beyond any training run's need of a fresh world.
MAX_EPISODES_PER_WORLD = 10**9
#: Physics sub-steps per control period by default (1/120 s at the default 0.1 s).
PHYSICS_SUBSTEPS = 12


@dataclass(frozen=True)
class Rule:
    """Allowed values described in words; checked in :meth:`EnvConfig.__post_init__` or
    by the config it builds (:class:`CameraConfig`, :class:`RobotConfig`)."""

    text: str

    def check(self, name: str, value: Any, unit: str) -> Any:
        return value

    def __str__(self) -> str:
        return self.text


@dataclass(frozen=True)
class Range(Rule):
    """A real number (an integer when ``integer``) between ``low`` and ``high``, or
    ``None`` when ``optional``."""

    text: str = ""
    low: float = 0.0
    high: float = 1.0
    integer: bool = False
    low_open: bool = False
    high_open: bool = False
    optional: bool = False

    def check(self, name: str, value: Any, unit: str) -> float | None:
        if value is None and self.optional:
            return None
        return require_number(name, value, self.low, self.high, unit, integer=self.integer,
                              low_open=self.low_open, high_open=self.high_open)

    def __str__(self) -> str:
        kind = "integer in " if self.integer else ""
        return (kind + interval(self.low, self.high, self.integer, self.low_open,
                                self.high_open) + (", or `None`" if self.optional else "")
                + (f"; {self.text}" if self.text else ""))


@dataclass(frozen=True)
class Positive(Rule):
    """A real number above zero."""

    text: str = ""

    def check(self, name: str, value: Any, unit: str) -> float:
        return require_positive(name, value, unit)

    def __str__(self) -> str:
        return "> 0" + (f"; {self.text}" if self.text else "")


@dataclass(frozen=True)
class Choices(Rule):
    """One of ``values``."""

    text: str = ""
    values: tuple = ()

    def check(self, name: str, value: Any, unit: str) -> Any:
        if value not in self.values:
            raise ValueError(f"unknown {name} {value!r}; allowed: {self.values}")
        return value

    def __str__(self) -> str:
        return ", ".join(f"`{v!r}`" for v in self.values) + (f"; {self.text}" if self.text
                                                             else "")


@dataclass(frozen=True)
class HeightOrRange(Rule):
    """``None``, a real number in ``[low, high]``, or a pair ``(a, b)`` of them with
    ``a <= b`` (stored as a tuple of floats)."""

    text: str = ""
    low: float = 0.0
    high: float = 1.0

    def check(self, name: str, value: Any, unit: str) -> float | tuple[float, float] | None:
        if value is None or is_real(value):
            return Range(low=self.low, high=self.high, optional=True).check(name, value, unit)
        pair = require_sequence(name, value, 2, f"a number or a pair (low, high) in "
                                f"{interval(self.low, self.high)} {unit}")
        low, high = (require_number(name, v, self.low, self.high, unit) for v in pair)
        if low > high:
            raise ValueError(f"{name} {value!r}: the pair's low end is above its high end; "
                             f"give (low, high) with low <= high")
        return (low, high)

    def __str__(self) -> str:
        return (f"{interval(self.low, self.high)}, a pair (low, high) in it, or `None`"
                + (f"; {self.text}" if self.text else ""))


def _arg(default: Any, allowed: Rule, unit: str, meaning: str) -> Any:
    """A field of :class:`EnvConfig` with its row of the field table."""
    return dataclasses.field(default=default, metadata={"allowed": allowed, "unit": unit,
                                                        "meaning": meaning})


RAYCAST_ONLY = "`renderer='raycast'` only"


@dataclass(frozen=True)
class EnvConfig:
    """The arguments of :class:`homing_gym.env.HomingEnv`, checked on construction: a bad
    value raises ``ValueError`` naming the argument, the value and what is allowed.
    Sequences are stored as tuples and numbers as floats (ints where counted). Checks
    that need the task are the env's: ``obs_keys`` against the task's keys, and
    ``drive="synchro"`` refused in a task that drives the robot itself."""

    render_mode: str | None = _arg(None, Choices(values=(None, *RENDER_MODES)), "",
                                   "`'rgb_array'`: top-down map beside current and goal "
                                   "panoramas; `'human'`: PyBullet's GUI")
    obs_keys: tuple[str, ...] = _arg(("panorama", "goal"),
                                     Rule("distinct keys of the observation table"), "",
                                     "the observation's keys")
    panorama_shape: tuple[int, int] = _arg(CameraConfig.panorama_shape, Rule(PANORAMA_SHAPES),
                                           "pixels", "panorama size (H, W)")
    vfov_deg: float = _arg(math.degrees(CameraConfig.vfov), Range(low=10, high=120),
                           "degrees", "vertical field of view, symmetric about the horizon")
    n_views: int = _arg(CameraConfig.n_views, Choices(values=N_VIEWS), "",
                        "perspective renders remapped into the panorama (`'tiny'`, `'egl'`)")
    renderer: str = _arg(CameraConfig.renderer, Choices(values=RENDERERS), "",
                         "`'raycast'`: exact ray casting; `'tiny'`: PyBullet's TinyRenderer "
                         "(homing-gym 0.1's default, 2-6x slower); `'egl'`: PyBullet's "
                         "OpenGL plugin")
    omni_size: int = _arg(CameraConfig.omni_size, Range(low=16, high=2048, integer=True),
                          "pixels", "side of the catadioptric `omni` images")
    supersampling: int = _arg(CameraConfig.supersampling,
                              Range(RAYCAST_ONLY, 1, 4, integer=True), "rays per pixel side",
                              "k x k rays averaged per panorama pixel")
    sky_color: tuple[float, float, float] | None = _arg(
        None, Rule(f"three RGB values in [0, 1], or `None`; {RAYCAST_ONLY}"), "",
        "colour of rays that hit nothing (`None`: the scene's)")
    shadows: bool | None = _arg(None, Rule(f"`True`, `False`, `None`; {RAYCAST_ONLY}"), "",
                                "objects cast shadows from the scene light (`None`: as the "
                                "world says, else none)")
    camera_height: float | tuple[float, float] | None = _arg(
        None, HeightOrRange(low=CAMERA_HEIGHT_RANGE[0], high=CAMERA_HEIGHT_RANGE[1]),
        "metres", f"camera above the floor (a pair: each episode's drawn uniformly from it; "
        f"`None`: the world's, else {RobotConfig.camera_height:g}; below the robot's top, "
        f"about 0.1 m, only the ray caster does not see the robot's body)")
    action_type: str = _arg("continuous", Choices(values=ACTION_TYPES), "",
                            "`Box(-1, 1, (2,))` (forward, yaw rate) or `Discrete(4)`")
    drive: str = _arg(RobotConfig.drive, Choices(values=DRIVES), "",
                      "`'synchro'`: the body translates without turning (continuous "
                      "actions `(vx, vy)`)")
    max_speed: float = _arg(RobotConfig.max_speed,
                            Positive("with `max_yaw_rate`, within the wheels' top speed"),
                            "m/s", "forward speed of action 1")
    max_yaw_rate: float = _arg(RobotConfig.max_yaw_rate, Positive(), "rad/s",
                               "yaw rate of action 1, counter-clockwise")
    stop_threshold: float = _arg(0.05, Range(low=0, high=1, high_open=True), "",
                                 "a continuous action with both components below it is stop")
    control_period: float = _arg(0.1, Range(low=0, high=MAX_CONTROL_PERIOD, low_open=True),
                                 "s", "time each action is held")
    physics_substeps: int = _arg(
        PHYSICS_SUBSTEPS, Range(f"physics steps of [1/{round(1 / MIN_TIME_STEP)}, "
                                f"1/{round(1 / MAX_TIME_STEP)}] s", 1, MAX_SUBSTEPS,
                                integer=True), "", "physics steps per control period")
    motion: str = _arg("pybullet", Choices(values=MOTIONS), "",
                       "how the robot moves: PyBullet's physics, or a kinematic unicycle "
                       "that obstacles stop (faster; differential drive and "
                       f"{RAYCAST_ONLY}; `homing_gym.sim.kinematic` says how it differs)")
    odometry_noise: float = _arg(0.02, Range(low=0, high=MAX_ODOMETRY_NOISE), "",
                                 "each encoder increment scaled by 1 + N(0, noise)")
    odometry_origin: str = _arg("start", Choices(values=ODOMETRY_ORIGINS), "",
                                "`odometry` starts at zero (`'start'`) or at the start pose "
                                "in home's frame (`'home'`: privileged)")
    lighting_change: float = _arg(0.0, Range(low=0, high=1), "",
                                  "strength of an illumination change between the snapshot "
                                  "and the run (0: none)")
    goal_step_length: float = _arg(0.15, Range(low=0, high=1, low_open=True), "metres",
                                   "the `goal_step` snapshot this far ahead of the goal")
    episodes_per_world: int = _arg(1, Range(low=1, high=MAX_EPISODES_PER_WORLD, integer=True),
                                   "", "unseeded resets per procedural world (a seeded "
                                   "reset always draws a new one)")

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):
            value = f.metadata["allowed"].check(f.name, getattr(self, f.name),
                                                f.metadata["unit"])
            object.__setattr__(self, f.name, value)
            if f.name == "render_mode" and value == "human" and (why := gui_unavailable()):
                raise ValueError(f"render_mode='human' opens PyBullet's GUI, which cannot "
                                 f"open here: {why}; use render_mode='rgb_array' (frames as "
                                 f"arrays)")
        self._check_combinations()
        if isinstance(self.obs_keys, list):
            object.__setattr__(self, "obs_keys", tuple(self.obs_keys))
        object.__setattr__(self, "panorama_shape", require_sequence(
            "panorama_shape", self.panorama_shape, 2, "(H, W) integers"))
        self.robot(), self.camera()            # their own checks (wheel speeds, shape)

    def _check_combinations(self) -> None:
        """Checks of arguments that depend on one another."""
        time_step = self.control_period / self.physics_substeps
        if not MIN_TIME_STEP <= time_step <= MAX_TIME_STEP:
            raise ValueError(
                f"control_period {self.control_period!r} s in {self.physics_substeps} "
                f"physics_substeps gives physics steps of {time_step:.3g} s; allowed: steps "
                f"in [1/{round(1 / MIN_TIME_STEP)}, 1/{round(1 / MAX_TIME_STEP)}] s "
                f"(PyBullet's contacts fail beyond)")
        raycast = self.renderer == "raycast"
        if self.supersampling != CameraConfig.supersampling and not raycast:
            raise ValueError(f"supersampling needs renderer='raycast', got "
                             f"renderer={self.renderer!r}")
        if self.sky_color is not None:
            if not raycast:
                raise ValueError(f"sky_color needs renderer='raycast' (the {self.renderer!r} "
                                 f"renderer's background is fixed), got "
                                 f"renderer={self.renderer!r}")
            what = "three RGB values in [0, 1]"
            rgb = require_sequence("sky_color", self.sky_color, 3, what)
            if not all(is_real(c) and 0 <= c <= 1 for c in rgb):
                raise ValueError(f"sky_color must be {what}, got {self.sky_color!r}")
            object.__setattr__(self, "sky_color", rgb)
        if self.shadows not in (True, False, None):
            raise ValueError(f"shadows must be True, False or None, got {self.shadows!r}")
        if self.shadows and not raycast:
            raise ValueError(f"shadows needs renderer='raycast', got "
                             f"renderer={self.renderer!r}")
        if self.motion == "kinematic" and (self.drive != "differential" or not raycast):
            raise ValueError(f"motion='kinematic' needs drive='differential' and "
                             f"renderer='raycast' (the robot has no body for PyBullet to "
                             f"draw), got drive={self.drive!r}, renderer={self.renderer!r}")
        if self.drive == "synchro" and self.action_type != "continuous":
            raise ValueError("drive='synchro' takes continuous actions (vx, vy); got "
                             f"action_type={self.action_type!r}")

    def robot(self, world_camera_height: float | None = None,
              rng: np.random.Generator | None = None) -> RobotConfig:
        """The robot's settings, its camera ``camera_height`` metres up (a pair: drawn
        uniformly from it by ``rng``, its low end without one), else
        ``world_camera_height`` (a world's appearance), else the robot's default."""
        height = self.camera_height
        if isinstance(height, tuple):
            height = height[0] if rng is None else float(rng.uniform(*height))
        height = next((h for h in (height, world_camera_height) if h is not None),
                      RobotConfig.camera_height)
        return RobotConfig(max_speed=self.max_speed, max_yaw_rate=self.max_yaw_rate,
                           camera_height=height, drive=self.drive)

    def camera(self) -> CameraConfig:
        """The panoramic camera's settings."""
        return CameraConfig(panorama_shape=self.panorama_shape,
                            vfov=math.radians(self.vfov_deg), n_views=self.n_views,
                            omni_size=self.omni_size, renderer=self.renderer,
                            supersampling=self.supersampling)


class Argument(NamedTuple):
    """One row of an argument table: name, type, default, allowed values, unit, meaning."""

    name: str
    type: str
    default: Any
    allowed: str
    unit: str
    meaning: str


def field_table() -> tuple[Argument, ...]:
    """The rows of :class:`EnvConfig`'s fields, in order."""
    return tuple(Argument(f.name, str(f.type), f.default, str(f.metadata["allowed"]),
                          f.metadata["unit"], f.metadata["meaning"])
                 for f in dataclasses.fields(EnvConfig))


def env_config(kwargs: dict[str, Any]) -> EnvConfig:
    """:class:`EnvConfig` of ``kwargs``; ``ValueError`` naming the unknown ones and
    listing the known (instead of Python's ``TypeError``, which names one and lists none)."""
    known = [f.name for f in dataclasses.fields(EnvConfig)]
    unknown = sorted(set(kwargs) - set(known))
    if unknown:
        raise ValueError(f"HomingEnv got unknown keyword arguments {unknown}; allowed: "
                         f"{sorted(known)}")
    return EnvConfig(**kwargs)
