"""A batch of envs spread over worker processes, for machines with more cores than one
process can use (PyBullet keeps the GIL: a process steps its robots on one core).

:class:`ProcessBatch` has :class:`~homing_gym.vector.batch.EnvBatch`'s interface.
Each of its ``processes`` spawned workers holds an :class:`EnvBatch` of a contiguous
share of the envs and answers a whole vector step with one message; the observations
go through shared memory (one block per worker and key), not the pipe. Env ``i``
behaves as in one process (same seeds, same automatic resets), so results do not depend
on the split. A worker whose env fails reports the env's index and error once; a worker
that dies is reported with its envs; either way every worker is stopped and the shared
memory freed. Workers ignore Ctrl-C (the main process closes them) and end when the
main process does (their pipe closes).
"""

from __future__ import annotations

import multiprocessing as mp
import signal
from collections.abc import Callable, Sequence
from multiprocessing import shared_memory
from typing import Any

import numpy as np
from gymnasium import spaces
from gymnasium.vector import AutoresetMode

from homing_gym.env import HomingEnv
from homing_gym.vector.batch import EnvBatch, EnvFailedError, StepResults
from homing_gym.vector.worlds import WorldBuilder, start_builder, stop_builder

#: Seconds a closing worker may take before it is killed.
CLOSE_TIMEOUT = 10.0
#: Errors a worker reports as themselves (bad seeds or options, unknown attributes);
#: others come as ``RuntimeError`` naming their type.
_CALLER_ERRORS = {"ValueError": ValueError, "AttributeError": AttributeError,
                  "TypeError": TypeError}


def _attached(names: dict[str, str], space: spaces.Dict, n: int
              ) -> tuple[list[shared_memory.SharedMemory], dict[str, np.ndarray]]:
    """The shared blocks ``names[key]`` (keep them while the views live) and views
    ``(n, ...)`` of each key's."""
    blocks = [shared_memory.SharedMemory(name=names[key]) for key in space.spaces]
    views = {key: np.ndarray((n, *space[key].shape), space[key].dtype, buffer=block.buf)
             for key, block in zip(space.spaces, blocks)}
    return blocks, views


def _serve(conn, makers: list[Callable[[], HomingEnv]], first: int, threads: int,
           max_episode_steps: int | None, mode: AutoresetMode) -> None:
    """A worker: build the batch, then answer commands until ``close`` or a closed pipe."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        batch = EnvBatch(makers, threads=threads, max_episode_steps=max_episode_steps,
                         mode=mode, first_index=first)
    except Exception as err:      # e.g. envs that cannot be batched: said in the main process
        conn.send(("error", (type(err).__name__, str(err))))
        return
    conn.send(("ready", (batch.observation_space, batch.action_space,
                         bool(batch.prebuildable))))
    names, builder = conn.recv()
    if builder is not None:
        batch.use_builder(WorldBuilder(builder))
    blocks, views = _attached(names, batch.observation_space, batch.num_envs)

    def write() -> None:
        for key, view in views.items():
            for i, obs in enumerate(batch.obs):
                view[i] = obs[key]

    try:
        while True:
            command, data = conn.recv()
            try:
                if command == "reset":
                    answer = batch.reset(*data)
                elif command == "step":
                    r = batch.step(data)
                    answer = (r.rewards, r.terminated, r.truncated, r.infos)
                elif command in ("call", "set_attr"):
                    answer = getattr(batch, command)(*data)
                elif command == "served":
                    answer = batch.worlds_served
                else:
                    break
            except EnvFailedError as err:
                conn.send(("failed", (err.index, err.error)))
                break
            except Exception as err:    # noqa: BLE001  a bad seed, an unknown attribute, a
                conn.send(("error", (type(err).__name__, str(err))))    # step before reset
                continue
            if command in ("reset", "step"):
                write()
            conn.send(("ok", answer))
    except (EOFError, OSError):         # the main process is gone
        pass
    finally:
        batch.close()
        for block in blocks:
            block.close()
        conn.close()


class ProcessBatch:
    """The envs made by ``makers`` in ``processes`` spawned workers (contiguous shares),
    each rendering with ``threads`` threads; as :class:`EnvBatch` otherwise. With
    ``prebuild_worlds`` each worker whose envs draw procedural worlds gets a builder
    process of its own (:mod:`homing_gym.vector.worlds`), started here (a worker is a
    daemon and may not start one) and stopped with the batch."""

    def __init__(self, makers: Sequence[Callable[[], HomingEnv]], processes: int, *,
                 threads: int = 1, max_episode_steps: int | None = None,
                 mode: AutoresetMode = AutoresetMode.NEXT_STEP, prebuild_worlds: bool = False):
        self.num_envs = len(makers)
        bounds = np.linspace(0, self.num_envs, processes + 1).round().astype(int)
        #: ``(first, stop)`` env indices of each worker's share.
        self.shares = [(int(a), int(b)) for a, b in zip(bounds[:-1], bounds[1:])]
        ctx = mp.get_context("spawn")
        self._conns, self._processes, self._blocks = [], [], []
        #: The world builder processes started for workers (``prebuild_worlds``).
        self.builders: list[mp.Process] = []
        self._views: list[dict[str, np.ndarray]] = []
        self.closed = False
        self.started = False
        try:
            for first, stop in self.shares:
                parent, child = ctx.Pipe()
                process = ctx.Process(target=_serve, daemon=True, name=f"homing-env-{first}",
                                      args=(child, list(makers[first:stop]), first, threads,
                                            max_episode_steps, mode))
                process.start()
                child.close()
                self._conns.append(parent)
                self._processes.append(process)
            ready = self._answers(range(len(self.shares)))
            spaces_of = [answer[:2] for answer in ready]
            self.observation_space, self.action_space = spaces_of[0]
            for w, (obs_space, act_space) in enumerate(spaces_of[1:], 1):
                if (obs_space, act_space) != spaces_of[0]:
                    raise ValueError(f"env {self.shares[w][0]} cannot be batched with env 0: "
                                     f"its spaces {obs_space}, {act_space} differ from "
                                     f"{spaces_of[0]}")
            for w, (conn, (first, stop)) in enumerate(zip(self._conns, self.shares)):
                views = {}
                for key, space in self.observation_space.spaces.items():
                    shape = (stop - first, *space.shape)
                    block = shared_memory.SharedMemory(
                        create=True, size=max(1, int(np.prod(shape)) * space.dtype.itemsize))
                    self._blocks.append(block)
                    views[key] = np.ndarray(shape, space.dtype, buffer=block.buf)
                builder = None
                if prebuild_worlds and ready[w][2]:      # the worker's envs draw worlds
                    process, builder = start_builder(f"homing-worlds-{first}")
                    self.builders.append(process)
                conn.send(({key: block.name for key, block in
                            zip(views, self._blocks[-len(views):])}, builder))
                if builder is not None:
                    builder.close()          # the worker holds it now
                self._views.append(views)
        except BaseException:
            self.close()
            raise

    def stacked_obs(self) -> dict[str, np.ndarray]:
        """The latest observations as one batch (each key ``(N, ...)``)."""
        return {key: np.concatenate([views[key] for views in self._views])
                for key in self.observation_space.spaces}

    def _send(self, w: int, message: tuple) -> None:
        """Send ``message`` to worker ``w``; a dead worker's pipe is said by
        :meth:`_answers`."""
        try:
            self._conns[w].send(message)
        except OSError:
            pass

    def _answers(self, workers: Sequence[int]) -> list[Any]:
        """The answers of ``workers``, each read before any error is raised (so that no
        answer is left in a pipe): an env's failure, or a worker's death, closes
        everything; a caller's error (a bad seed, an unknown attribute) leaves the envs."""
        answers, error = [], None
        for w in workers:
            first, stop = self.shares[w]
            try:
                status, data = self._conns[w].recv()
            except (EOFError, ConnectionResetError, OSError):
                self._processes[w].join(1.0)
                status, data = "failed", (first, f"its worker process (envs {first}-{stop - 1})"
                                                 f" died with exit code "
                                                 f"{self._processes[w].exitcode}")
            if status == "failed":
                error = error or EnvFailedError(*data)
            elif status == "error":
                kind, message = data
                error = error or _CALLER_ERRORS.get(kind, RuntimeError)(
                    message if kind in _CALLER_ERRORS else f"{kind}: {message}")
            answers.append(data)
        if isinstance(error, EnvFailedError):
            self.close()
        if error is not None:
            raise error
        return answers

    def reset(self, seeds: Sequence[int | None], options: dict | None = None,
              mask: np.ndarray | None = None) -> list[dict[str, Any] | None]:
        for w, (first, stop) in enumerate(self.shares):
            self._send(w, ("reset", (list(seeds[first:stop]), options,
                                     None if mask is None else mask[first:stop])))
        answers = self._answers(range(len(self.shares)))
        self.started = True
        return [info for infos in answers for info in infos]

    def step(self, actions: Sequence[Any]) -> StepResults:
        for w, (first, stop) in enumerate(self.shares):
            self._send(w, ("step", actions[first:stop]))
        answers = self._answers(range(len(self.shares)))
        rewards, terminated, truncated, infos = zip(*answers)
        return StepResults(np.concatenate(rewards), np.concatenate(terminated),
                           np.concatenate(truncated), [i for part in infos for i in part])

    @property
    def worlds_served(self) -> int:
        """New worlds the envs took from the workers' builders so far."""
        for w in range(len(self.shares)):
            self._send(w, ("served", None))
        return sum(self._answers(range(len(self.shares))))

    def _per_worker(self, command: str, data_of: Callable[[list[int], list[int]], tuple],
                    indices: Sequence[int] | None) -> list[Any]:
        """Send ``command`` with ``data_of(local indices, positions)`` to each worker
        holding envs of ``indices`` (default: all); the answers in the order of
        ``indices``."""
        indices = list(range(self.num_envs) if indices is None else indices)
        asked = []
        for w, (first, stop) in enumerate(self.shares):
            positions = [k for k, i in enumerate(indices) if first <= i < stop]
            if positions:
                local = [indices[k] - first for k in positions]
                self._send(w, (command, data_of(local, positions)))
                asked.append((w, positions))
        answers: list[Any] = [None] * len(indices)
        for (_, positions), values in zip(asked, self._answers([w for w, _ in asked])):
            for k, value in zip(positions, values or [None] * len(positions)):
                answers[k] = value
        return answers

    def call(self, name: str, args: tuple = (), kwargs: dict | None = None,
             indices: Sequence[int] | None = None) -> list[Any]:
        return self._per_worker("call", lambda local, _: (name, args, kwargs, local), indices)

    def set_attr(self, name: str, values: Sequence[Any],
                 indices: Sequence[int] | None = None) -> None:
        values = list(values)
        self._per_worker("set_attr", lambda local, positions: (
            name, [values[k] for k in positions], local), indices)

    def close(self) -> None:
        """Stop every worker and free the shared memory; safe to call more than once."""
        if self.closed:
            return
        self.closed = True
        for conn in self._conns:
            try:
                conn.send(("close", None))
            except (BrokenPipeError, ConnectionResetError, OSError):
                pass
        for process in self._processes:
            process.join(CLOSE_TIMEOUT)
            if process.is_alive():
                process.kill()
                process.join()
        for process in self.builders:      # told to stop by their workers, or orphaned
            stop_builder(process)
        for conn in self._conns:
            conn.close()
        self._views = []
        for block in self._blocks:
            block.close()
            block.unlink()
