"""The learner alone: how fast PPO's inference and updates run for a policy's network, on
any device, with the environments taken out of the measurement.

``homing-train --benchmark`` measures a whole configuration (envs, inference, updates) on
the machine it runs on. This module answers the other half of the question, "if the
envs were free, how many env steps per second could this learner take?", which is what
decides whether a GPU is worth it (issue 19): it builds the network of a saved policy
(architecture and spaces read from the zip with :func:`~homing_train.learning.policy_zip.load_policy`,
nothing unpickled), feeds it random observations of the same spaces from a vectorised
env that costs nothing (:class:`FreeVecEnv`), and times SB3's own ``PPO.learn`` with
:func:`homing_train.learning.throughput.measure`. It imports neither PyBullet nor
:mod:`homing_gym`, so it runs on a machine where only torch and stable-baselines3 are
installed::

    python -m homing_train.learning.learner_throughput --policy train/shipped/ppo_procedural_long.zip \\
        --device cuda --n-envs 8 64 256 --batch-size 256 1024

Network cost does not depend on pixel values, so random observations time the same
arithmetic as real ones. ``target_kl`` is off, so every update runs all ``n_epochs``
(the shipped run's ``target_kl`` can end an update early; this measures the full one).
"""

from __future__ import annotations

import argparse
import time
from dataclasses import dataclass

import numpy as np
from gymnasium import spaces
from stable_baselines3.common.vec_env import VecEnv

from homing_train.learning.throughput import Throughput, measure


class FreeVecEnv(VecEnv):
    """``num_envs`` envs of the given spaces whose steps cost nothing: observations drawn
    once from the spaces (``pool`` of them, served in turn), reward 0, every episode
    ``episode_steps`` long. For timing a learner, never for learning."""

    def __init__(self, num_envs: int, observation_space: spaces.Space,
                 action_space: spaces.Space, seed: int = 0, pool: int = 16,
                 episode_steps: int = 100):
        super().__init__(num_envs, observation_space, action_space)
        observation_space.seed(seed)
        self._pool = [self._batch(observation_space) for _ in range(pool)]
        self._next = 0
        self._t = 0
        self._episode_steps = episode_steps

    def _batch(self, space: spaces.Space):
        samples = [space.sample() for _ in range(self.num_envs)]
        if isinstance(space, spaces.Dict):
            return {key: np.stack([s[key] for s in samples]) for key in space.spaces}
        return np.stack(samples)

    def _observation(self):
        self._next = (self._next + 1) % len(self._pool)
        return self._pool[self._next]

    def reset(self):
        self._t = 0
        return self._observation()

    def step_async(self, actions) -> None:
        self._t += 1

    def step_wait(self):
        done = self._t % self._episode_steps == 0
        dones = np.full(self.num_envs, done)
        obs = self._observation()
        infos = [{"terminal_observation": None} if done else {} for _ in range(self.num_envs)]
        return obs, np.zeros(self.num_envs, np.float32), dones, infos

    def close(self) -> None:
        pass

    def get_attr(self, attr_name, indices=None):
        if attr_name == "render_mode":
            return [None] * self.num_envs
        raise AttributeError(attr_name)

    def set_attr(self, attr_name, value, indices=None) -> None:
        raise AttributeError(attr_name)

    def env_method(self, method_name, *args, indices=None, **kwargs):
        raise AttributeError(method_name)

    def env_is_wrapped(self, wrapper_class, indices=None):
        return [False] * self.num_envs


@dataclass
class LearnerThroughput:
    """One learner measurement: the PPO settings, the device, and the rates."""

    device: str
    n_envs: int
    n_steps: int
    batch_size: int
    n_epochs: int
    timesteps: int                    # env steps that PPO.learn took in the timed run
    rates: Throughput

    @property
    def update_cap(self) -> float:
        """Env steps per second PPO could take if rollouts cost nothing at all."""
        return self.timesteps / max(self.rates.update_s, 1e-9)

    @property
    def update_samples_per_s(self) -> float:
        """Samples through forward, backward and Adam per second during updates."""
        return self.update_cap * self.n_epochs


def measure_learner(policy_path: str, device: str, n_envs: int, n_steps: int, batch_size: int,
                    n_epochs: int, steps: int, seed: int = 0) -> LearnerThroughput:
    """Time the network of the PPO zip at ``policy_path`` as a learner on ``device``:
    inference on batches of ``n_envs`` and ``PPO.learn`` for ``steps`` env steps (at
    least one rollout) on a :class:`FreeVecEnv`."""
    from stable_baselines3 import PPO
    from stable_baselines3.common.logger import Logger

    from homing_train.learning.policy_zip import load_policy
    from homing_train.learning.ppo_settings import check_device

    if min(n_envs, n_steps, batch_size, n_epochs) < 1:
        raise ValueError(f"n_envs, n_steps, batch_size and n_epochs must be at least 1, got "
                         f"{n_envs}, {n_steps}, {batch_size}, {n_epochs}")
    check_device(device)
    loaded = load_policy(policy_path)
    net = loaded.policy
    policy_kwargs = {"net_arch": net.net_arch, "activation_fn": net.activation_fn,
                     "features_extractor_class": net.features_extractor_class,
                     "features_extractor_kwargs": net.features_extractor_kwargs,
                     "share_features_extractor": net.share_features_extractor}
    env = FreeVecEnv(n_envs, loaded.observation_space, loaded.action_space, seed=seed)
    model = PPO(type(net), env, n_steps=n_steps, batch_size=batch_size, n_epochs=n_epochs,
                target_kl=None, policy_kwargs=policy_kwargs, device=device, seed=seed, verbose=0)
    model.set_logger(Logger(None, []))     # SB3's default makes a folder in /tmp per run
    steps = max(steps, n_steps * n_envs)
    model.learn(n_steps * n_envs, progress_bar=False)         # warm-up: kernels, allocator
    rates = measure(env, model, steps, f"{device}, {n_envs} envs, batch {batch_size}")
    return LearnerThroughput(str(model.device), n_envs, n_steps, batch_size, n_epochs,
                             model.num_timesteps, rates)


def table(rows: list[LearnerThroughput]) -> str:
    """A Markdown table of learner measurements."""
    lines = ["| device | envs | n_steps | batch | epochs | inference samples/s (batch = envs) "
             "| PPO env steps/s, envs free | update share | update samples/s "
             "| update cap (env steps/s) |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        lines.append(f"| {r.device} | {r.n_envs} | {r.n_steps} | {r.batch_size} | "
                     f"{r.n_epochs} | {r.rates.inference_per_s:,.0f} | "
                     f"{r.rates.ppo_steps_per_s:,.0f} | {100 * r.rates.update_share:.0f}% | "
                     f"{r.update_samples_per_s:,.0f} | {r.update_cap:,.0f} |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m homing_train.learning.learner_throughput",
        description="Time a saved policy's network as a PPO learner, envs taken out "
                    "(random observations of its spaces), on any torch device.")
    parser.add_argument("--policy", default="train/shipped/ppo_procedural_long.zip",
                        help="SB3 PPO zip whose network and spaces are timed")
    parser.add_argument("--device", nargs="+", default=["cpu"], help="torch devices, e.g. cpu cuda")
    parser.add_argument("--n-envs", type=int, nargs="+", default=[8])
    parser.add_argument("--batch-size", type=int, nargs="+", default=[256])
    parser.add_argument("--n-steps", type=int, default=128)
    parser.add_argument("--n-epochs", type=int, default=4)
    parser.add_argument("--rollouts", type=int, default=4,
                        help="rollouts timed per row (after one warm-up rollout)")
    parser.add_argument("--torch-threads", type=int,
                        help="torch.set_num_threads (default: torch's own)")
    args = parser.parse_args(argv)
    import torch
    from tqdm import tqdm

    if args.torch_threads is not None:
        torch.set_num_threads(args.torch_threads)
    combos = [(d, e, b) for d in args.device for e in args.n_envs for b in args.batch_size
              if b <= args.n_steps * e]
    if not combos:
        parser.error(f"every --batch-size is larger than a rollout (n_steps x n_envs = "
                     f"{args.n_steps} x {max(args.n_envs)})")
    rows = []
    t0 = time.perf_counter()
    try:
        for device, n_envs, batch in tqdm(combos, desc="learner", unit="row"):
            rows.append(measure_learner(args.policy, device, n_envs, args.n_steps, batch,
                                        args.n_epochs, args.rollouts * args.n_steps * n_envs))
    except (ValueError, RuntimeError) as err:
        parser.exit(2, f"learner_throughput: error: {err}\n")
    finally:
        if rows:
            print(table(rows))
    print(f"\n{args.policy}; torch {torch.__version__}, {torch.get_num_threads()} CPU threads"
          + (f", {torch.cuda.get_device_name()}" if torch.cuda.is_available() else "")
          + f"; {time.perf_counter() - t0:.0f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
