"""Envs in fewer subprocesses than envs: each worker steps a group of them.

SB3's ``SubprocVecEnv`` gives every env a process of its own and a pipe round trip (a
pickled action, a pickled observation) per env and step. For a homing env, whose step
takes well under a millisecond at the training resolution, that round trip costs about as
much as the step (docs/training.md, "End to end on the GPU machine"). Here each of
``workers`` processes holds a ``DummyVecEnv`` of its share of the envs (contiguous
ranks), steps them in turn and answers with one message for the whole group. Env ``i``
behaves exactly as in ``DummyVecEnv`` and ``SubprocVecEnv`` (same seeds, same automatic
reset with ``terminal_observation``), so results do not depend on the grouping.
"""

from __future__ import annotations

import multiprocessing as mp
from collections.abc import Callable, Sequence
from typing import Any

import gymnasium as gym
import numpy as np
from stable_baselines3.common.vec_env.base_vec_env import CloudpickleWrapper, VecEnv


def _group_worker(remote, parent_remote, env_fns: CloudpickleWrapper) -> None:
    """Serve one group's ``DummyVecEnv`` over ``remote`` until ``close``."""
    from stable_baselines3.common.vec_env import DummyVecEnv

    parent_remote.close()
    vec = DummyVecEnv(env_fns.var)
    try:
        while True:
            try:
                cmd, data = remote.recv()
            except EOFError:
                break
            if cmd == "step":
                remote.send(vec.step(data))
            elif cmd == "reset":
                vec._seeds, vec._options = data
                remote.send((vec.reset(), vec.reset_infos))
            elif cmd == "env_method":
                name, args, kwargs, local = data
                remote.send(vec.env_method(name, *args, indices=local, **kwargs))
            elif cmd == "get_attr":
                remote.send(vec.get_attr(data[0], data[1]))
            elif cmd == "set_attr":
                vec.set_attr(data[0], data[1], data[2])
                remote.send([None] * len(data[2]))
            elif cmd == "is_wrapped":
                remote.send(vec.env_is_wrapped(data[0], data[1]))
            elif cmd == "spaces":
                remote.send((vec.observation_space, vec.action_space))
            elif cmd == "close":
                remote.send(None)
                break
            else:
                raise ValueError(f"grouped worker: unknown command {cmd!r}")
    except KeyboardInterrupt:
        pass
    finally:
        vec.close()


def _concatenate(parts: list, space: gym.Space):
    if isinstance(space, gym.spaces.Dict):
        return {key: np.concatenate([p[key] for p in parts]) for key in space.spaces}
    return np.concatenate(parts)


class GroupedSubprocVecEnv(VecEnv):
    """``len(env_fns)`` envs in ``workers`` subprocesses (``1 <= workers <= len(env_fns)``),
    each stepping a contiguous group; ``start_method`` as in ``multiprocessing``."""

    def __init__(self, env_fns: Sequence[Callable[[], gym.Env]], workers: int,
                 start_method: str = "spawn"):
        n = len(env_fns)
        if not 1 <= workers <= n:
            raise ValueError(f"workers must be between 1 and the number of envs ({n}); "
                             f"got {workers}")
        bounds = np.linspace(0, n, workers + 1).round().astype(int)
        #: ``(first, stop)`` env ranks of each worker's group.
        self.groups = [(int(a), int(b)) for a, b in zip(bounds[:-1], bounds[1:])]
        ctx = mp.get_context(start_method)
        self.remotes, self.processes = [], []
        for first, stop in self.groups:
            remote, work_remote = ctx.Pipe()
            process = ctx.Process(target=_group_worker, daemon=True,
                                  args=(work_remote, remote,
                                        CloudpickleWrapper(list(env_fns[first:stop]))))
            process.start()
            work_remote.close()
            self.remotes.append(remote)
            self.processes.append(process)
        self.remotes[0].send(("spaces", None))
        observation_space, action_space = self.remotes[0].recv()
        super().__init__(n, observation_space, action_space)
        self.closed = False

    def _local(self, indices) -> list[tuple[int, list[int], list[int]]]:
        """``(worker, local indices, positions in the request)`` of the env ``indices``
        (all envs when None)."""
        ranks = self._get_indices(indices)
        out = []
        for w, (first, stop) in enumerate(self.groups):
            positions = [k for k, i in enumerate(ranks) if first <= i < stop]
            if positions:
                out.append((w, [ranks[k] - first for k in positions], positions))
        return out

    def step_async(self, actions: np.ndarray) -> None:
        for remote, (first, stop) in zip(self.remotes, self.groups):
            remote.send(("step", actions[first:stop]))

    def step_wait(self):
        results = [remote.recv() for remote in self.remotes]
        obs, rewards, dones, infos = zip(*results)
        return (_concatenate(list(obs), self.observation_space), np.concatenate(rewards),
                np.concatenate(dones), [info for group in infos for info in group])

    def reset(self):
        for remote, (first, stop) in zip(self.remotes, self.groups):
            remote.send(("reset", (self._seeds[first:stop], self._options[first:stop])))
        results = [remote.recv() for remote in self.remotes]
        self.reset_infos = [info for _, infos in results for info in infos]
        self._reset_seeds()
        self._reset_options()
        return _concatenate([obs for obs, _ in results], self.observation_space)

    def _ask(self, cmd: str, make_data, indices) -> list[Any]:
        """Each env's answer to ``cmd``, in the order of ``indices``."""
        located = self._local(indices)
        for w, local, _ in located:
            self.remotes[w].send((cmd, make_data(local)))
        answers: list[Any] = [None] * sum(len(positions) for _, _, positions in located)
        for w, _, positions in located:
            for k, value in zip(positions, self.remotes[w].recv()):
                answers[k] = value
        return answers

    def env_method(self, method_name: str, *method_args, indices=None, **method_kwargs):
        return self._ask("env_method", lambda local: (method_name, method_args, method_kwargs,
                                                      local), indices)

    def get_attr(self, attr_name: str, indices=None):
        return self._ask("get_attr", lambda local: (attr_name, local), indices)

    def set_attr(self, attr_name: str, value: Any, indices=None) -> None:
        self._ask("set_attr", lambda local: (attr_name, value, local), indices)

    def env_is_wrapped(self, wrapper_class, indices=None):
        return self._ask("is_wrapped", lambda local: (wrapper_class, local), indices)

    def close(self) -> None:
        if self.closed:
            return
        for remote in self.remotes:
            try:
                remote.send(("close", None))
                remote.recv()
            except (EOFError, BrokenPipeError, ConnectionResetError):
                pass
        for process in self.processes:
            process.join()
        self.closed = True
