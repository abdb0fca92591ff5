"""``homing-benchmark --vec native``: the native vector env against one env in one process.

For each world, in the same run: env steps per second of one env in one process
(``single``, the reference) and of the native vector env with ``num_envs`` envs in one
process and in each number of ``processes`` asked for. Each of ``rounds`` rounds runs
a block of every configuration in turn and medians are reported, so that load from
other processes hits all of them alike. Actions are random, and each env stops (ends its
episode) with probability ``1 / episode_steps`` per step, so episodes last about
``episode_steps`` steps, at different times in different envs, as a trained policy's do.
Procedural worlds are measured with a new world every episode (``episodes_per_world=1``).

For each vector env the table also gives the median and 99th-percentile time of one
vector step, and in one process the share of the vector steps' time spent resetting envs
(new worlds built, goal snapshots taken): what a step waits for. For each number of
worker processes ``K`` > 1 it also runs ``K`` independent processes of one env each at
once (``independent xK``, after the rounds): the env steps per second the cores give
without any batching, the ceiling of a vector env on this machine; and how rendering
alone scales: each process renders panoramas at its robot's pose by itself (the others
waiting), then all at once; the sum over the processes of their rate at once over their
rate alone is ``K`` where the cores do not slow each other down.
"""

from __future__ import annotations

import multiprocessing as mp
import queue
import time
from dataclasses import dataclass

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from tqdm import tqdm

from homing_gym.scenes import scene_factory


@dataclass(frozen=True)
class VectorResult:
    """One configuration's env steps per second (median over rounds); for vector envs
    also their step times (seconds), in one process the share of them spent in resets;
    for the single env the time (seconds per step) in PyBullet's physics (the sub-steps,
    motor updates and contact checks) and in rendering; for ``independent xK`` how
    rendering alone scales over the ``K`` processes (``K`` at best)."""

    world: str
    config: str
    steps_per_s: float
    step_p50: float | None = None
    step_p99: float | None = None
    reset_share: float | None = None
    physics_s: float | None = None
    render_s: float | None = None
    render_scaling: float | None = None


class _Timed:
    """Wraps ``obj.name`` (an instance's method) to add up the seconds spent in it."""

    def __init__(self, obj, name: str):
        self.seconds, self._inner = 0.0, getattr(obj, name)
        setattr(obj, name, self)

    def __call__(self, *args, **kwargs):
        start = time.perf_counter()
        try:
            return self._inner(*args, **kwargs)
        finally:
            self.seconds += time.perf_counter() - start


def _stop_action(space: spaces.Space):
    return 3 if isinstance(space, spaces.Discrete) else np.zeros(space.shape, space.dtype)


def _actions(space: spaces.Space, n: int, p_stop: float, rng: np.random.Generator) -> np.ndarray:
    """``n`` random actions of ``space``, each the stop action with probability ``p_stop``."""
    actions = np.array([space.sample() for _ in range(n)])
    actions[rng.random(n) < p_stop] = _stop_action(space)
    return actions


def _stepped(env: gym.Env, actions: np.ndarray) -> float:
    """Env steps per second of ``env`` taking ``actions`` (reset when an episode ends)."""
    start = time.perf_counter()
    for a in actions:
        _, _, terminated, truncated, _ = env.step(a)
        if terminated or truncated:
            env.reset()
    return len(actions) / (time.perf_counter() - start)


def _rendered(env: gym.Env, count: int) -> float:
    """Panoramas per second of ``env``'s camera rendering ``count`` at its robot's pose."""
    u = env.unwrapped
    start = time.perf_counter()
    for _ in range(count):
        u.render_panorama(u.pose)
    return count / (time.perf_counter() - start)


def _independent(env_id: str, settings: dict, steps: int, p_stop: float, seed: int,
                 barrier, rates) -> None:
    """One of the independent processes: make and reset its env, wait for the others,
    then step; then render ``steps // 4`` panoramas alone (each process in its turn) and
    at once with the others. Its env steps per second and panoramas per second at once
    over alone go to ``rates``."""
    env = gym.make(env_id, **settings)
    try:
        env.reset(seed=seed)
        env.action_space.seed(seed)
        actions = _actions(env.action_space, steps, p_stop, np.random.default_rng(seed))
        barrier.wait(timeout=300.0)     # a sibling that failed breaks it: no hang
        stepped = _stepped(env, actions)
        count = max(steps // 4, 1)
        for turn in range(barrier.parties):
            barrier.wait(timeout=300.0)
            if turn == seed:
                alone = _rendered(env, count)
        barrier.wait(timeout=300.0)
        rates.put((stepped, _rendered(env, count) / alone))
    finally:
        env.close()


def independent_rates(env_id: str, settings: dict, processes: int, steps: int,
                      p_stop: float) -> tuple[float, float]:
    """Env steps per second of ``processes`` spawned processes of one env each, started
    together, ``steps`` steps each (the sum of their rates), and how rendering scales
    over them (:func:`_independent`); ``RuntimeError`` naming a process that died."""
    ctx = mp.get_context("spawn")
    barrier, rates = ctx.Barrier(processes), ctx.Queue()
    workers = [ctx.Process(target=_independent, daemon=True, name=f"homing-bench-{k}",
                           args=(env_id, settings, steps, p_stop, k, barrier, rates))
               for k in range(processes)]
    try:
        for w in workers:
            w.start()
        got: list[tuple[float, float]] = []
        while len(got) < processes:
            try:
                got.append(rates.get(timeout=1.0))
            except queue.Empty:
                dead = [w for w in workers if w.exitcode not in (None, 0)]
                if dead:
                    raise RuntimeError(f"benchmark process {dead[0].name} died with exit "
                                       f"code {dead[0].exitcode}") from None
        return float(sum(g[0] for g in got)), float(sum(g[1] for g in got))
    finally:
        for w in workers:
            w.join(5.0)
            if w.is_alive():
                w.kill()


def world_settings(world: str, world_kwargs: dict) -> dict:
    """Env kwargs of ``world`` (:func:`homing_gym.benchmark.world_kwargs`); a procedural
    scene draws a new world every episode."""
    scene = world_kwargs.get("scene")
    procedural = isinstance(scene, str) and scene_factory(scene).randomised
    return {**world_kwargs, **({"episodes_per_world": 1} if procedural else {})}


def run(worlds: dict[str, dict], num_envs: int, processes: list[int], steps: int,
        rounds: int = 10, episode_steps: int = 45, shape: tuple[int, int] = (48, 256),
        env_id: str = "homing_gym/LocalHoming-v0") -> list[VectorResult]:
    """Measure every world: ``steps`` env steps per configuration and round."""
    results = []
    p_stop = 1.0 / episode_steps
    for world, kwargs in worlds.items():
        settings = {**world_settings(world, kwargs), "panorama_shape": shape}
        single = gym.make(env_id, **settings)
        single.reset(seed=0)
        physics = _Timed(single.unwrapped.sim, "step")      # the kinematic robot's too
        render = _Timed(single.unwrapped.camera, "render")
        single_steps = 0
        vectors = {p: gym.make_vec(env_id, num_envs=num_envs, processes=p,
                                   vectorization_mode="vector_entry_point", **settings)
                   for p in processes}
        rng = np.random.default_rng(0)
        rates: dict[str, list[float]] = {"single": [], **{f"native x{p}": [] for p in processes}}
        times: dict[int, list[float]] = {p: [] for p in processes}    # vector steps (s)
        resets = [0.0, 0.0]                     # seconds resetting, seconds stepping
        try:
            for v in vectors.values():
                v.action_space.seed(0)
                v.reset(seed=0)
            single.action_space.seed(0)
            for _ in tqdm(range(rounds), desc=f"{world}: single env and vector envs in turn"):
                rates["single"].append(_stepped(single, _actions(single.action_space, steps,
                                                                  p_stop, rng)))
                single_steps += steps
                for p, v in vectors.items():
                    batch = v.unwrapped.batch
                    before = getattr(batch, "reset_seconds", 0.0)
                    start = time.perf_counter()
                    for _ in range(max(steps // num_envs, 1)):
                        t0 = time.perf_counter()
                        v.step(_actions(v.single_action_space, num_envs, p_stop, rng))
                        times[p].append(time.perf_counter() - t0)
                    elapsed = time.perf_counter() - start
                    rates[f"native x{p}"].append(max(steps // num_envs, 1) * num_envs / elapsed)
                    if p == 1:
                        resets[0] += batch.reset_seconds - before
                        resets[1] += elapsed
        finally:
            single.close()
            for v in vectors.values():
                v.close()
        independent = {p: independent_rates(env_id, settings, p, steps * rounds // 2, p_stop)
                       for p in processes if p > 1}
        results.append(VectorResult(world, "single", float(np.median(rates.pop("single"))),
                                    physics_s=physics.seconds / single_steps,
                                    render_s=render.seconds / single_steps))
        for p in processes:
            step_times = times[p]
            results.append(VectorResult(
                world, f"native x{p}", float(np.median(rates[f"native x{p}"])),
                float(np.median(step_times)), float(np.percentile(step_times, 99)),
                resets[0] / resets[1] if p == 1 else None))
        results += [VectorResult(world, f"independent x{p}", rate, render_scaling=scaling)
                    for p, (rate, scaling) in independent.items()]
    return results


def table(results: list[VectorResult], num_envs: int) -> str:
    """A Markdown table; ``vs single``: env steps/s over one env's in the same world and
    run."""
    single = {r.world: r.steps_per_s for r in results if r.config == "single"}
    lines = ["| world | configuration | env steps/s | vs single | vector step p50 (ms) | "
             "p99 (ms) | p99 / p50 | time in resets |", "|---|---|---:|---:|---:|---:|---:|---:|"]
    split = [f"* {r.world}, one env: {1e3 * r.physics_s:.3f} ms of physics and "
             f"{1e3 * r.render_s:.3f} ms of rendering per step, of "
             f"{1e3 / r.steps_per_s:.3f} ms ({100 * r.physics_s * r.steps_per_s:.0f}% "
             f"physics; resets included)" for r in results if r.physics_s is not None]
    split += [f"* {r.world}, rendering alone in {r.config.split('x')[-1]} independent "
              f"processes at once: {r.render_scaling:.2f}x one process's rate"
              for r in results if r.render_scaling is not None]
    for r in results:
        count = r.config.split("x")[-1]
        config = ("single" if r.config == "single" else
                  f"{count} independent processes of one env each (the cores' ceiling)"
                  if r.config.startswith("independent") else
                  f"native, {num_envs} envs in {count} process"
                  + ("es" if count != "1" else ""))
        share = "-" if r.reset_share is None else f"{100 * r.reset_share:.0f}%"
        timing = ("| - | - | - | - |" if r.step_p50 is None else
                  f"| {1e3 * r.step_p50:.2f} | {1e3 * r.step_p99:.2f} | "
                  f"{r.step_p99 / r.step_p50:.2f} | {share} |")
        lines.append(f"| {r.world} | {config} | {r.steps_per_s:.0f} | "
                     f"{r.steps_per_s / single[r.world]:.2f}x {timing}")
    return "\n".join(lines + [""] + split)
