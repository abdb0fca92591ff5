"""The controller interface: stable-baselines3 call shape, paper-style moves inside.

A scripted controller is a dataclass whose fields are its parameters (with the papers'
defaults). The harness drives it exactly like a stable-baselines3 model::

    action, state = controller.predict(observation, state=None, episode_start=True)

Subclasses implement :meth:`Controller.decide`: from the current observation, return the
next :class:`~homing_baselines.motion.Move` (home vector: direction in the robot frame and step
length) or ``None`` to stop (arrived). The base class executes each move over several env
steps with the shared :class:`~homing_baselines.motion.MotionHelper`, asks for the next decision
once the move is done, and records the commanded direction in :attr:`last_direction` and
the controller's latest home-direction estimate in :attr:`last_home_direction` (robot
frame at the time of the decision; used by the homing vector field).

Controllers see the observation only. The harness gives an env handle only to
controllers that declare ``needs_env = True`` (oracles, named as such), through
:meth:`Controller.attach_env`.
"""

from __future__ import annotations

import dataclasses
import math
from abc import ABC, abstractmethod
from typing import Any, ClassVar

import numpy as np

from homing_baselines.motion import MOTION_STYLES, MotionHelper, MotionSpec, Move
from homing_gym.validation import is_real


@dataclasses.dataclass
class Controller(ABC):
    """Base class of scripted controllers. Fields common to all of them:

    ``motion``: ``"turn_then_drive"``, ``"pursuit"`` or ``"reversing"`` (see
    :mod:`homing_baselines.motion`).
    """

    motion: str = "turn_then_drive"

    #: Registry name (set by :func:`homing_baselines.register`).
    name: ClassVar[str] = ""
    #: True only for oracle controllers: the harness then calls :meth:`attach_env`.
    needs_env: ClassVar[bool] = False
    #: What the method knows beyond the robot's own images and odometry (ground truth
    #: from the simulator or the scene), named beside its row in every table; "" if
    #: nothing.
    privileged: ClassVar[str] = ""
    #: True when every move heads for the controller's home estimate, so the move's
    #: direction is :attr:`last_home_direction`. Controllers that first probe (distance
    #: estimation takes a measuring step) set False and set the attribute themselves.
    moves_home: ClassVar[bool] = True
    #: Env ids the method is made for; ``None``: any env with ``panorama`` and ``goal``.
    envs: ClassVar[tuple[str, ...] | None] = None
    #: Scenes it needs (e.g. distinctly coloured landmarks); ``None``: any scene.
    scenes: ClassVar[tuple[str, ...] | None] = None
    #: True when the controller reads the observation only when it decides, never while
    #: :meth:`predict` plays a queued move: the harness may then let the env skip the
    #: images in between (:meth:`needs_next_observation`). Controllers that watch every
    #: step or override :meth:`predict` keep False.
    reads_at_decisions_only: ClassVar[bool] = False

    @classmethod
    def made_for(cls, env_id: str, scene: str) -> bool:
        """Whether the method applies to ``env_id`` in scene ``scene`` (what
        ``homing-suite`` runs by default)."""
        return ((cls.envs is None or env_id in cls.envs)
                and (cls.scenes is None or scene in cls.scenes))

    def __post_init__(self) -> None:
        if self.motion not in MOTION_STYLES:
            raise ValueError(f"{type(self).__name__}: unknown motion {self.motion!r}; "
                             f"allowed: {MOTION_STYLES}")
        self._check_parameter_kinds()
        self.validate()
        self._helper = MotionHelper(MotionSpec(), self.motion)
        self._queue: list = []
        self._seed: int | None = None
        self.last_direction: float | None = None
        self.last_home_direction: float | None = None
        self.last_move: Move | None = None
        self._goal: np.ndarray | None = None

    def _check_parameter_kinds(self) -> None:
        """``ValueError`` for a parameter not of its default's kind: ``True``/``False``
        where the default is a bool, text where it is a str, a finite number where it is
        a number (infinite only where the default is). Ranges are :meth:`validate`'s."""
        for f in dataclasses.fields(self):
            default, value = f.default, getattr(self, f.name)
            if isinstance(default, bool):
                ok, kind = isinstance(value, (bool, np.bool_)), "True or False"
            elif isinstance(default, str):
                ok, kind = isinstance(value, str), "text"
            elif isinstance(default, (int, float)):
                ok = is_real(value) or (not math.isfinite(default) and value == default)
                kind = "a finite number"
            else:
                continue
            if not ok:
                raise ValueError(f"{type(self).__name__}: parameter {f.name} must be {kind}, "
                                 f"got {value!r}")

    # -- to override -----------------------------------------------------------------------
    def validate(self) -> None:
        """Check the parameter values; raise ``ValueError`` with a clear message."""

    @abstractmethod
    def decide(self, observation: dict[str, np.ndarray]) -> Move | None:
        """The next move from the current observation, or ``None`` to stop."""

    def on_reset(self) -> None:
        """Clear per-episode memory (called by :meth:`reset`)."""

    def keeps_memory_across_episodes(self) -> bool:
        """Whether an episode depends on the episodes before it (a map kept per world):
        the harness then runs all episodes in order, in one process."""
        return False

    def observation_keys(self) -> tuple[str, ...]:
        """The env observation keys this controller reads (the harness asks the env for
        them when the user did not choose ``obs_keys``)."""
        return ("panorama", "goal")

    # -- the interface the harness uses ------------------------------------------------------
    def configure(self, spec: MotionSpec) -> None:
        """Tell the controller the env's command interface (action type and limits)."""
        self._helper = MotionHelper(spec, self.motion)

    @property
    def motion_spec(self) -> MotionSpec:
        return self._helper.spec

    @property
    def last_travel(self) -> float | None:
        """Direction (radians, CCW, in the robot's frame now) in which the last move
        translated the robot, once that move has been played (the open-loop plan's, not
        a measurement); None before the episode's first translation."""
        return self._helper.travel

    def attach_env(self, env) -> None:
        """Only for ``needs_env`` controllers (oracles); others refuse."""
        raise TypeError(f"controller {self.name or type(self).__name__!r} decides from "
                        f"observations only and must not be given the env")

    def reset(self, seed: int | None = None) -> None:
        """Start a new episode: forget the current move and per-episode memory.
        ``seed`` (the episode seed) makes stochastic controllers reproducible."""
        self._queue = []
        self._helper.reset()
        self._seed = seed
        self.last_direction = None
        self.last_home_direction = None
        self.last_move = None
        self._goal = None
        self.on_reset()

    def is_new_goal(self, goal: np.ndarray) -> bool:
        """Whether the goal image ``goal`` differs from the one of the last call (an
        episode's first, or a route's next target: RouteFollowing-v0 advances it); it is
        kept (a copy) for the next call."""
        if self._goal is not None and np.array_equal(goal, self._goal):
            return False
        self._goal = np.array(goal, copy=True)
        return True

    def predict(self, observation: dict[str, np.ndarray], state: Any = None,
                episode_start: Any = None, deterministic: bool = True) -> tuple[Any, Any]:
        """The next env action, stable-baselines3 style. ``episode_start`` true resets
        the controller (as :meth:`reset` without a seed). Returns ``(action, state)``."""
        if episode_start is not None and bool(np.any(episode_start)):
            self.reset(self._seed)
        if not self._queue:
            move = self.decide(observation)
            self.last_move = move
            if move is None:
                return self._helper.stop_action(), state
            self.last_direction = float(move.direction)
            if self.moves_home:
                self.last_home_direction = self.last_direction
            self._queue = self._helper.plan(move)
            if not self._queue:  # a move below the command resolution: stop this step
                return self._helper.stop_action(), state
        return self._queue.pop(0), state

    def needs_next_observation(self) -> bool:
        """Whether the next :meth:`predict` reads its observation: always, unless
        :attr:`reads_at_decisions_only` and a move is still queued."""
        return not (self.reads_at_decisions_only and self._queue)

    def params(self) -> dict[str, Any]:
        """The parameter values (dataclass fields) as a plain dict."""
        return dataclasses.asdict(self)
