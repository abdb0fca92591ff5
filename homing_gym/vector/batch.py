"""Many homing envs stepped together in one process: the core of the native vector env.

A step of :class:`EnvBatch` moves every robot in turn (PyBullet keeps the GIL, so the
physics of one process runs on one core), then renders their panoramas in threads (the
ray caster's kernels release the GIL, so they render on every core). Rendering each
panorama as soon as its robot has moved, beside the next robots' physics, was slower:
the render threads then wait for the GIL that the physics holds. New worlds of
procedural scenes are built ahead of need in a :class:`~homing_gym.vector.worlds.WorldBuilder`
process (``prebuild_worlds``). Each env is an ordinary :class:`~homing_gym.env.HomingEnv`,
stepped exactly as alone (the same calls in the same order on its own PyBullet client,
caster and random generator), so env ``i`` of a batch reset with seed ``s + i`` gives
the observations, rewards and infos of ``gym.make(...)`` reset with that seed,
automatic resets included.

The batch ends episodes after ``max_episode_steps`` (``truncated``, as Gymnasium's
``TimeLimit``) and resets finished envs by Gymnasium's ``AutoresetMode``; it knows
nothing of how Gymnasium or Stable-Baselines3 lay out a vector step's results
(:mod:`homing_gym.vector.native`, and the SB3 adapter in ``homing_train``).
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Sequence
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass
from typing import Any

import numpy as np
from gymnasium.vector import AutoresetMode

from homing_gym.env import HomingEnv
from homing_gym.vector.worlds import WorldBuilder

#: Most envs in one vector env (each holds a PyBullet world, a ray caster and its
#: buffers: several MiB).
MAX_NUM_ENVS = 1024
#: Most render threads of one batch.
MAX_THREADS = 256


class EnvFailedError(RuntimeError):
    """Env ``index`` of a vector env raised inside a step or reset; the vector env is
    closed, and the env's own error is the ``__cause__`` (or, from a worker process,
    its traceback is in the message)."""

    def __init__(self, index: int, error: str):
        super().__init__(f"env {index} failed: {error} (the vector env is closed)")
        self.index, self.error = index, error


def checked_count(name: str, value, largest: int) -> int:
    """``value`` as an int in ``[1, largest]``; else a ``ValueError`` naming ``name``."""
    if (isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer))
            or not 1 <= value <= largest):
        raise ValueError(f"{name} must be an integer from 1 to {largest}, got {value!r}")
    return int(value)


def cores() -> int:
    """Cores this process may run on."""
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1


def autoreset_mode(mode) -> AutoresetMode:
    """Gymnasium's ``AutoresetMode`` of ``mode`` (a member or its value)."""
    try:
        return AutoresetMode(mode)
    except ValueError:
        allowed = [m.value for m in AutoresetMode]
        raise ValueError(f"unknown autoreset_mode {mode!r}; allowed: AutoresetMode members "
                         f"or their values {allowed}") from None


def episode_limit(max_episode_steps) -> int | None:
    """``max_episode_steps`` checked: an integer >= 1, or ``None`` (no limit)."""
    if max_episode_steps is not None and (
            isinstance(max_episode_steps, (bool, np.bool_))
            or not isinstance(max_episode_steps, (int, np.integer)) or max_episode_steps < 1):
        raise ValueError(f"max_episode_steps must be an integer >= 1 or None, "
                         f"got {max_episode_steps!r}")
    return None if max_episode_steps is None else int(max_episode_steps)


@dataclass
class StepResults:
    """One vector step: each env's info (with ``SAME_STEP``, an env that finished
    carries ``final_obs`` and ``final_info`` in it, and its observation is the first of
    its next episode), and the rewards and episode ends as arrays."""

    rewards: np.ndarray
    terminated: np.ndarray
    truncated: np.ndarray
    infos: list[dict[str, Any]]


class EnvBatch:
    """The envs made by ``makers`` (functions returning a
    :class:`~homing_gym.env.HomingEnv`), whose observation and action spaces must be
    equal (``ValueError`` naming the first env that differs). ``threads`` render the
    panoramas (default: one per core); episodes end after ``max_episode_steps``;
    ``mode`` is the Gymnasium autoreset mode; ``prebuild_worlds`` builds procedural
    worlds ahead of need. Actions are checked by the caller."""

    def __init__(self, makers: Sequence[Callable[[], HomingEnv]], *, threads: int | None = None,
                 max_episode_steps: int | None = None,
                 mode: AutoresetMode = AutoresetMode.NEXT_STEP, first_index: int = 0,
                 prebuild_worlds: bool = False):
        self.num_envs = len(makers)
        threads = (min(self.num_envs, cores()) if threads is None
                   else checked_count("threads", threads, MAX_THREADS))
        self.max_episode_steps = episode_limit(max_episode_steps)
        self.mode = autoreset_mode(mode)
        self._first = first_index          # this batch's env 0 in the whole vector env
        self.envs: list[HomingEnv] = []
        self._pool: ThreadPoolExecutor | None = None
        self.closed = False
        try:
            for maker in makers:
                self.envs.append(maker())
            first = self.envs[0]
            for i, env in enumerate(self.envs[1:], 1):
                for what in ("observation_space", "action_space"):
                    if getattr(env, what) != getattr(first, what):
                        raise ValueError(
                            f"env {first_index + i} cannot be batched with env "
                            f"{first_index}: its {what} {getattr(env, what)} differs from "
                            f"{getattr(first, what)} (give the envs settings that agree on it)")
        except BaseException:
            self.close()
            raise
        self.observation_space = first.observation_space
        self.action_space = first.action_space
        self._threads = threads
        self._pool = ThreadPoolExecutor(threads, "homing-render") if threads > 1 else None
        self._builder: WorldBuilder | None = None
        if prebuild_worlds and self.prebuildable:
            self.use_builder(WorldBuilder())
        self._elapsed = np.zeros(self.num_envs, np.int64)
        self._autoreset = np.zeros(self.num_envs, np.bool_)
        self.obs: list[dict[str, np.ndarray] | None] = [None] * self.num_envs
        self.started = False
        #: Seconds spent resetting envs so far (new worlds, goal snapshots).
        self.reset_seconds = 0.0

    def reset(self, seeds: Sequence[int | None], options: dict | None = None,
              mask: np.ndarray | None = None) -> list[dict[str, Any] | None]:
        """Reset the envs where ``mask`` is true (all by default) with their ``seeds``;
        each env's info (``None`` where not reset). The observations are in :attr:`obs`."""
        if mask is not None and not self.started:
            raise ValueError("the first reset resets every env: reset without a mask")
        infos: list[dict[str, Any] | None] = [None] * self.num_envs
        for i in range(self.num_envs) if mask is None else np.flatnonzero(mask):
            infos[i] = self._reset(int(i), seeds[i], options)
        self.started = True
        return infos

    def _reset(self, i: int, seed: int | None = None, options: dict | None = None
               ) -> dict[str, Any]:
        start = time.perf_counter()
        try:
            self.obs[i], info = self.envs[i].reset(seed=seed, options=options)
        except ValueError:          # a bad seed or option: the caller's to fix
            raise
        except Exception as err:
            raise self._failed(i, err) from err
        self._elapsed[i] = 0
        self._autoreset[i] = False
        self.reset_seconds += time.perf_counter() - start
        return info

    def step(self, actions: Sequence[Any]) -> StepResults:
        """Step every env with its action (``NEXT_STEP``: an env whose episode ended at
        the last step is reset instead, and its action ignored)."""
        if not self.started:
            raise RuntimeError("call reset() before step()")
        n = self.num_envs
        if self.mode is AutoresetMode.DISABLED and self._autoreset.any():
            raise RuntimeError(f"envs {(self._first + np.flatnonzero(self._autoreset)).tolist()} "
                               f"ended their episodes: reset them with options="
                               f"{{'reset_mask': mask}} (autoreset_mode DISABLED)")
        rewards = np.zeros(n, np.float64)
        terminated = np.zeros(n, np.bool_)
        truncated = np.zeros(n, np.bool_)
        infos: list[dict[str, Any]] = [{}] * n
        moved: dict[int, tuple[float, bool, dict[str, Any], bool]] = {}
        pending: dict[int, Future] = {}
        ended = (self._autoreset.copy() if self.mode is AutoresetMode.NEXT_STEP
                 else np.zeros(n, np.bool_))           # reset at this step, not stepped
        try:
            for i in np.flatnonzero(~ended).tolist():
                env = self.envs[i]
                try:
                    moved[i] = env.advance(actions[i])
                except Exception as err:
                    raise self._failed(i, err) from err
            if self._pool is not None:      # PyBullet keeps the GIL: render after physics
                drawn = [(i, self.envs[i]) for i, (_, _, _, skip) in moved.items()
                         if not skip and self.envs[i].reads_panorama]
                pending = {k: self._pool.submit(_render_all, drawn[k::self._threads])
                           for k in range(min(self._threads, len(drawn)))}
            # the envs whose episodes ended reset while the others' panoramas render
            for i in np.flatnonzero(ended).tolist():
                infos[i] = self._reset(i)
            for k in list(pending):
                failed = pending.pop(k).result()
                if failed is not None:
                    index, error = failed
                    raise self._failed(index, error) from error
            for i, (reward, term, info, skip) in moved.items():
                try:
                    self.obs[i] = self.envs[i].observation(skip)
                except Exception as err:
                    raise self._failed(i, err) from err
                self._elapsed[i] += 1
                rewards[i], terminated[i], infos[i] = reward, term, info
                truncated[i] = (self.max_episode_steps is not None
                                and self._elapsed[i] >= self.max_episode_steps)
                if self.mode is AutoresetMode.SAME_STEP and (term or truncated[i]):
                    final = {"final_obs": self.obs[i], "final_info": info}
                    infos[i] = {**self._reset(i), **final}
        finally:
            for future in pending.values():       # after an error: let the renders end
                future.exception()
        self._autoreset = terminated | truncated
        return StepResults(rewards, terminated, truncated, infos)

    def call(self, name: str, args: tuple = (), kwargs: dict | None = None,
             indices: Sequence[int] | None = None) -> list[Any]:
        """For each env of ``indices`` (default: all), its attribute ``name``, called with
        ``args`` and ``kwargs`` if it is a method."""
        values = []
        for i in range(self.num_envs) if indices is None else indices:
            value = getattr(self.envs[i], name)
            values.append(value(*args, **(kwargs or {})) if callable(value) else value)
        return values

    def set_attr(self, name: str, values: Sequence[Any],
                 indices: Sequence[int] | None = None) -> None:
        """Set attribute ``name`` of each env of ``indices`` (default: all) to its value."""
        for i, value in zip(range(self.num_envs) if indices is None else indices, values):
            setattr(self.envs[i], name, value)

    def _failed(self, index: int, error: BaseException) -> EnvFailedError:
        failed = EnvFailedError(self._first + index, f"{type(error).__name__}: {error}")
        self.close()
        return failed

    def stacked_obs(self) -> dict[str, np.ndarray]:
        """The envs' latest observations as one batch (each key ``(N, ...)``)."""
        return stacked(self.obs)

    @property
    def prebuildable(self) -> list[HomingEnv]:
        """The envs whose new worlds a :class:`~homing_gym.vector.worlds.WorldBuilder`
        can build: a registered procedural scene (by name) and the ray caster."""
        return [env for env in self.envs if isinstance(env.scene_spec, str)
                and env.draws_worlds and env.sim.caster is not None]

    def use_builder(self, builder: WorldBuilder) -> None:
        """Have ``builder`` build the new worlds of the :attr:`prebuildable` envs ahead
        of need (closed with the batch)."""
        self._builder = builder
        for env in self.prebuildable:
            env.world_source = builder.source(env.scene_spec, env.config.sky_color,
                                              env.config.shadows)

    @property
    def worlds_served(self) -> int:
        """New worlds the envs took from the builder so far (0 without one)."""
        return 0 if self._builder is None else self._builder.served

    def close(self) -> None:
        """Close every env and stop the render threads; safe to call more than once."""
        if self._pool is not None:
            self._pool.shutdown(wait=True)
            self._pool = None
        if getattr(self, "_builder", None) is not None:
            self._builder.close()
            self._builder = None
        for env in self.envs:
            env.close()
        self.closed = True


def _render_all(envs: list[tuple[int, HomingEnv]]) -> tuple[int, Exception] | None:
    """Render the panoramas of ``envs`` (index, env) in turn (one render thread's
    share); the index and error of the first that fails, else ``None``."""
    for i, env in envs:
        try:
            env.render_panorama_now()
        except Exception as err:        # noqa: BLE001  said by the caller, with the index
            return i, err
    return None


def stacked(observations: Sequence[dict[str, np.ndarray]]) -> dict[str, np.ndarray]:
    """Per-env observations as one batch: each key's values stacked along a new first axis."""
    return {key: np.stack([o[key] for o in observations]) for key in observations[0]}
