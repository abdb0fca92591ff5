"""Stable-Baselines3's ``VecEnv`` over homing-gym's native vector env (``--vec native``).

The envs step in one process (:class:`homing_gym.vector.batch.EnvBatch`: panoramas
rendered in threads) or in ``processes`` workers, each stepping its share as one batch
(:class:`homing_gym.vector.processes.ProcessBatch`: one message per worker and step,
observations through shared memory). SB3's conventions on top: an env whose episode
ends is reset at once (Gymnasium's ``SAME_STEP``), its last observation in
``info["terminal_observation"]`` and ``info["TimeLimit.truncated"]`` set when the step
limit, not the task, ended it. Episode returns, lengths and ``is_success`` are logged
by SB3's ``VecMonitor`` (:func:`native_vec_env`). Env ``i`` with seed ``seed + i`` runs
the episodes of ``DummyVecEnv``'s env ``i``.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from gymnasium.vector import AutoresetMode
from stable_baselines3.common.vec_env import VecMonitor
from stable_baselines3.common.vec_env.base_vec_env import VecEnv

from homing_gym.vector.native import NativeVectorEnv


class NativeVecEnv(VecEnv):
    """``len(env_kwargs)`` envs of ``env_id`` (env ``i`` made with ``env_kwargs[i]``) in
    ``processes`` processes (1: this one), ``threads`` render threads each."""

    def __init__(self, env_id: str, env_kwargs: Sequence[dict[str, Any]], processes: int = 1,
                 threads: int | None = None):
        self.venv = NativeVectorEnv(env_id, num_envs=len(env_kwargs),
                                    autoreset_mode=AutoresetMode.SAME_STEP,
                                    processes=processes, threads=threads,
                                    env_kwargs=list(env_kwargs))
        self.batch = self.venv.batch
        self._actions: np.ndarray | None = None
        super().__init__(self.venv.num_envs, self.venv.single_observation_space,
                         self.venv.single_action_space)

    def reset(self):
        infos = self.batch.reset(list(self._seeds),
                                 self._options[0] if self._options[0] else None)
        self.reset_infos = [info or {} for info in infos]
        self._reset_seeds()
        self._reset_options()
        return self.batch.stacked_obs()

    def step_async(self, actions: np.ndarray) -> None:
        self._actions = self.venv.checked_actions(actions)

    def step_wait(self):
        results = self.batch.step(self._actions)
        dones = results.terminated | results.truncated
        infos = []
        for info, term, trunc in zip(results.infos, results.terminated, results.truncated):
            if "final_obs" in info:
                info = {**info["final_info"], "terminal_observation": info["final_obs"],
                        "TimeLimit.truncated": bool(trunc and not term)}
            infos.append(info)
        return (self.batch.stacked_obs(), results.rewards.astype(np.float32), dones, infos)

    def close(self) -> None:
        self.venv.close()

    def get_attr(self, attr_name: str, indices=None) -> list[Any]:
        return self.batch.call(attr_name, indices=self._get_indices(indices))

    def set_attr(self, attr_name: str, value: Any, indices=None) -> None:
        indices = self._get_indices(indices)
        self.batch.set_attr(attr_name, [value] * len(indices), indices)

    def env_method(self, method_name: str, *method_args, indices=None, **method_kwargs):
        return self.batch.call(method_name, method_args, method_kwargs,
                               self._get_indices(indices))

    def env_is_wrapped(self, wrapper_class, indices=None) -> list[bool]:
        return [False] * len(self._get_indices(indices))    # the envs are bare


def native_vec_env(env_id: str, env_kwargs: Sequence[dict[str, Any]], processes: int = 1,
                   threads: int | None = None) -> VecMonitor:
    """:class:`NativeVecEnv` in SB3's ``VecMonitor`` (episode returns, lengths and
    ``is_success``, as ``Monitor`` logs them for ``DummyVecEnv``)."""
    return VecMonitor(NativeVecEnv(env_id, env_kwargs, processes, threads),
                      info_keywords=("is_success",))
