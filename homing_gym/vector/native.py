"""The native vector env: N robots in one process, behind Gymnasium 1.x's ``VectorEnv``.

>>> envs = gym.make_vec("homing_gym/LocalHoming-v0", num_envs=8,
...                     vectorization_mode="vector_entry_point")
>>> obs, infos = envs.reset(seed=0)          # env i: exactly gym.make(...).reset(seed=i)
>>> obs, rewards, terminated, truncated, infos = envs.step(envs.action_space.sample())

Every registered id has this vector entry point. The envs step as in
:class:`~homing_gym.vector.batch.EnvBatch` (physics in turn, panoramas rendered in
threads); observations come batched (each key ``(N, ...)``), infos as Gymnasium's
dict of arrays with ``_key`` masks. Episodes end after ``max_episode_steps`` (the id's,
as ``gym.make`` would wrap it) with ``truncated``. ``autoreset_mode`` is Gymnasium's:
``NEXT_STEP`` (the default: the step after an episode's end resets that env and
ignores its action), ``SAME_STEP`` (reset at once; ``infos["final_obs"]`` and
``infos["final_info"]``) or ``DISABLED`` (the caller resets with
``options={"reset_mask": mask}``).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from functools import partial
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from gymnasium.vector import AutoresetMode
from gymnasium.vector.utils import batch_space

from homing_gym.env import HomingEnv, check_env_kwargs
from homing_gym.vector.batch import MAX_NUM_ENVS, EnvBatch, checked_count, cores, episode_limit
from homing_gym.vector.batch import autoreset_mode as autoreset_mode_of
from homing_gym.vector.processes import ProcessBatch


def _creator(env_id: str) -> Callable[..., Any]:
    """What ``gym.make(env_id)`` calls to make the env (its entry point, loaded)."""
    entry = gym.spec(env_id).entry_point
    return gym.envs.registration.load_env_creator(entry) if isinstance(entry, str) else entry


def make_env(env_id: str, kwargs: dict[str, Any]) -> HomingEnv:
    """The bare env of ``env_id`` made with ``kwargs`` (the spec's own kwargs first), as
    ``gym.make`` would make it before its wrappers; ``ValueError`` when that is not a
    :class:`~homing_gym.env.HomingEnv` (top-level, so that worker processes can unpickle
    it)."""
    creator = _creator(env_id)
    if isinstance(creator, type) and issubclass(creator, HomingEnv):
        check_env_kwargs(creator, kwargs)
    env = creator(**{**gym.spec(env_id).kwargs, **kwargs})
    if not isinstance(env, HomingEnv):
        if hasattr(env, "close"):
            env.close()
        raise ValueError(f"{env_id!r} makes a {type(env).__name__}, not a homing_gym env: "
                         f"the native vector env steps HomingEnv instances directly (use "
                         f"vectorization_mode='sync' or 'async' for other envs)")
    return env


class NativeVectorEnv(gym.vector.VectorEnv):
    """``num_envs`` envs of ``env_id``. ``kwargs`` go to every env; ``env_kwargs``, a list
    of ``num_envs`` dicts, adds each env's own (e.g. a scene per env), as long as all envs
    keep one observation and action space (else ``ValueError``). ``processes``: 1 (the
    default) steps every env in this process; ``K > 1`` spreads them over ``K`` worker
    processes (:class:`~homing_gym.vector.processes.ProcessBatch`). ``threads``: render
    threads per process (default: the cores over the processes). ``prebuild_worlds``:
    a procedural scene's new worlds are built ahead of need in a background process
    (:mod:`homing_gym.vector.worlds`; one per worker process with ``processes`` > 1)."""

    def __init__(self, env_id: str, num_envs: int = 1, *,
                 max_episode_steps: int | None = None,
                 autoreset_mode: AutoresetMode | str = AutoresetMode.NEXT_STEP,
                 processes: int = 1, threads: int | None = None,
                 prebuild_worlds: bool = True, env_kwargs: Sequence[dict] | None = None,
                 **kwargs):
        self.num_envs = checked_count("num_envs", num_envs, MAX_NUM_ENVS)
        processes = checked_count("processes", processes, self.num_envs)
        mode = autoreset_mode_of(autoreset_mode)
        if env_kwargs is None:
            env_kwargs = [{}] * self.num_envs
        if (not isinstance(env_kwargs, Sequence) or len(env_kwargs) != self.num_envs
                or not all(isinstance(k, dict) for k in env_kwargs)):
            raise ValueError(f"env_kwargs must be a list of {self.num_envs} dicts (one per "
                             f"env), got {env_kwargs!r}")
        settings = [{**kwargs, **own} for own in env_kwargs]
        limits = [own.pop("max_episode_steps") for own in settings if "max_episode_steps" in own]
        if limits and (len(limits) < len(settings) or any(k != limits[0] for k in limits)):
            raise ValueError(f"the envs' max_episode_steps differ ({limits}, given for "
                             f"{len(limits)} of {len(settings)} envs): one vector env has "
                             f"one step limit")
        if limits:
            max_episode_steps = limits[0]
        makers = [partial(make_env, env_id, own) for own in settings]
        limit = episode_limit(gym.spec(env_id).max_episode_steps if max_episode_steps is None
                              else max_episode_steps)
        if threads is None:
            threads = max(1, cores() // processes)
        if not isinstance(prebuild_worlds, bool):
            raise ValueError(f"prebuild_worlds must be True or False, got {prebuild_worlds!r}")
        self.batch = (EnvBatch(makers, threads=threads, max_episode_steps=limit, mode=mode,
                               prebuild_worlds=prebuild_worlds)
                      if processes == 1 else
                      ProcessBatch(makers, processes, threads=threads,
                                   max_episode_steps=limit, mode=mode,
                                   prebuild_worlds=prebuild_worlds))
        self.max_episode_steps = limit
        self.metadata = {**getattr(_creator(env_id), "metadata", {}), "autoreset_mode": mode}
        self.autoreset_mode = mode
        self.render_mode = kwargs.get("render_mode")
        self.single_observation_space = self.batch.observation_space
        self.single_action_space = self.batch.action_space
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)

    # -- Gymnasium API --------------------------------------------------------------------
    def reset(self, *, seed: int | Sequence[int | None] | None = None,
              options: dict[str, Any] | None = None):
        """Reset every env (env ``i`` with ``seed + i``, or ``seed[i]``), or with
        ``options={"reset_mask": mask}`` those where ``mask`` is true."""
        self._check_open()
        seeds = self._seeds(seed)
        options = dict(options or {})
        mask = options.pop("reset_mask", None)
        if mask is not None and not (isinstance(mask, np.ndarray) and mask.dtype == np.bool_
                                     and mask.shape == (self.num_envs,) and mask.any()):
            raise ValueError(f"options['reset_mask'] must be a bool array of shape "
                             f"({self.num_envs},) with at least one True, got {mask!r}")
        infos = self._batched_infos(self.batch.reset(seeds, options or None, mask))
        return self.batch.stacked_obs(), infos

    def step(self, actions):
        self._check_open()
        results = self.batch.step(self.checked_actions(actions))
        return (self.batch.stacked_obs(), results.rewards, results.terminated,
                results.truncated, self._batched_infos(results.infos))

    def render(self) -> tuple[Any, ...] | None:
        """Each env's :meth:`~homing_gym.env.HomingEnv.render` (``rgb_array`` pictures;
        envs in this process only)."""
        self._check_open()
        if isinstance(self.batch, ProcessBatch):
            raise ValueError("render() needs the envs in this process (processes=1)")
        return tuple(env.render() for env in self.batch.envs)

    def call(self, name: str, *args, **kwargs) -> tuple[Any, ...]:
        """Each env's attribute ``name`` (called with ``args`` and ``kwargs`` if a method),
        as Gymnasium's ``SyncVectorEnv.call``."""
        self._check_open()
        return tuple(self.batch.call(name, args, kwargs))

    def get_attr(self, name: str) -> tuple[Any, ...]:
        """Each env's attribute ``name``."""
        return self.call(name)

    def set_attr(self, name: str, values: Any | Sequence[Any]) -> None:
        """Set each env's attribute ``name``: to ``values[i]`` given a list of
        ``num_envs`` values, else to ``values``."""
        self._check_open()
        if not (isinstance(values, (list, tuple)) and len(values) == self.num_envs):
            values = [values] * self.num_envs
        self.batch.set_attr(name, values)

    def close_extras(self, **kwargs) -> None:
        self.batch.close()

    # -- helpers --------------------------------------------------------------------------
    def _batched_infos(self, infos: Sequence[dict[str, Any] | None]) -> dict[str, Any]:
        """The envs' infos (``None`` where an env has none) in Gymnasium's layout (what
        ``VectorEnv._add_info`` builds env by env, here key by key): each key's values
        in an array of the first env's type (numbers), stacked (arrays), per env in an
        object array (other values, ``final_obs``, arrays whose shape differs between
        envs, such as a route's waypoints), nested dicts alike, with a ``_key`` mask of
        the envs that have it."""
        keys = dict.fromkeys(k for info in infos if info for k in info)
        out: dict[str, Any] = {}
        for key in keys:
            have = np.array([bool(info) and key in info for info in infos])
            values = [info[key] for info in infos if info and key in info]
            first = values[0]
            if isinstance(first, dict) and key != "final_obs":
                out[key] = self._batched_infos([info.get(key) if info else None
                                                for info in infos])
            elif key != "final_obs" and (type(first) in (int, float, bool)
                                         or issubclass(type(first), np.number)):
                out[key] = np.zeros(self.num_envs, dtype=type(first))
                out[key][have] = values
            elif (key != "final_obs" and isinstance(first, np.ndarray)
                  and all(isinstance(v, np.ndarray) and v.shape == first.shape
                          for v in values)):
                out[key] = np.zeros((self.num_envs, *first.shape), first.dtype)
                out[key][have] = values
            else:
                out[key] = np.full(self.num_envs, None, dtype=object)
                for i, value in zip(np.flatnonzero(have), values):
                    out[key][i] = value
            out[f"_{key}"] = have
        return out

    def _seeds(self, seed) -> list[int | None]:
        if seed is None:
            return [None] * self.num_envs
        if isinstance(seed, (int, np.integer)) and not isinstance(seed, (bool, np.bool_)):
            return [int(seed) + i for i in range(self.num_envs)]
        if (isinstance(seed, Sequence) and not isinstance(seed, str)
                and len(seed) == self.num_envs):
            return list(seed)
        raise ValueError(f"seed must be None, an integer (env i gets seed + i) or a list of "
                         f"{self.num_envs} seeds, got {seed!r}")

    def checked_actions(self, actions) -> np.ndarray:
        """``actions`` as an array of one action per env; ``ValueError`` naming the envs
        whose actions are not finite or not valid."""
        single = self.single_action_space
        a = np.asarray(actions)
        want = (self.num_envs, *single.shape)
        if a.shape != want or a.dtype.kind not in "iuf":
            raise ValueError(f"actions must be real numbers of shape {want} (one "
                             f"{single} action per env), got shape {a.shape}, dtype {a.dtype}")
        if isinstance(single, spaces.Discrete):
            bad = np.flatnonzero(~np.isin(a, np.arange(single.start, single.start + single.n)))
        else:
            bad = np.flatnonzero(~np.isfinite(a.reshape(self.num_envs, -1)).all(axis=1))
        if bad.size:
            raise ValueError(f"the actions of envs {bad.tolist()} are not valid "
                             f"{single} actions: {a[bad].tolist()}")
        return a.astype(single.dtype, copy=False)

    def _check_open(self) -> None:
        if self.closed or self.batch.closed:
            raise gym.error.ClosedEnvironmentError(
                "this vector env was closed (its envs are gone); make a new one")
