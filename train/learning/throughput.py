"""``homing-train --benchmark``: where PPO's time goes, for one training configuration.

Three measurements in one process, with the configuration's envs (``n_envs`` of them,
``vec`` workers), network and PPO settings:

* ``env``: env steps per second of the vectorised envs alone (``env.step``'s time only),
  with the model's own sampled actions: a trained network's episodes (``init_policy``)
  rather than a random one's, whose stop action ends most episodes within a few steps;
* ``inference``: samples per second of the policy's forward pass (sampling actions), on
  the batches of ``n_envs`` observations of the same loop, on one torch thread as during
  rollouts (:func:`~homing_train.learning.thread_split.phase_threads`);
* ``ppo``: env steps per second of ``PPO.learn`` end to end, split into the time spent
  collecting rollouts (envs and inference) and the time spent updating (``n_epochs``
  passes of minibatches of ``batch_size``), timed with SB3's rollout callbacks.

Nothing is written; the table goes to stdout. Rates are medians of nothing: one run of
``steps`` each, so compare configurations measured in the same session.
"""

from __future__ import annotations

import time
from dataclasses import dataclass


@dataclass
class Throughput:
    """Rates (per second) and the PPO time split of one configuration."""

    label: str
    n_envs: int
    env_steps_per_s: float
    inference_per_s: float
    ppo_steps_per_s: float
    rollout_s: float
    update_s: float

    @property
    def update_share(self) -> float:
        """Share of ``PPO.learn``'s time spent in updates."""
        return self.update_s / max(self.rollout_s + self.update_s, 1e-9)


def _rollout_timer():
    from stable_baselines3.common.callbacks import BaseCallback

    class RolloutTimer(BaseCallback):
        """Adds up the wall time between SB3's rollout start and end."""

        def __init__(self):
            super().__init__()
            self.rollout_s, self._t0 = 0.0, 0.0

        def _on_rollout_start(self) -> None:
            self._t0 = time.perf_counter()

        def _on_rollout_end(self) -> None:
            self.rollout_s += time.perf_counter() - self._t0

        def _on_step(self) -> bool:
            return True

    return RolloutTimer()


def measure(env, model, steps: int, label: str) -> Throughput:
    """Measure a vectorised ``env`` and a PPO ``model`` built on it (as ``homing-train``
    builds them) over ``steps`` env steps, each of the three parts; closes nothing."""
    import torch
    from stable_baselines3.common.logger import Logger

    from homing_train.learning.thread_split import phase_threads

    n_envs = env.num_envs
    rounds = max(steps // n_envs, 1)
    obs = env.reset()
    model.policy.set_training_mode(False)
    threads = torch.get_num_threads()
    torch.set_num_threads(1)
    env_s = inference_s = 0.0
    for _ in range(rounds):
        t0 = time.perf_counter()
        actions, _ = model.predict(obs, deterministic=False)
        t1 = time.perf_counter()
        obs = env.step(actions)[0]
        env_s, inference_s = env_s + time.perf_counter() - t1, inference_s + t1 - t0
    torch.set_num_threads(threads)
    env_rate, inference = rounds * n_envs / env_s, rounds * n_envs / inference_s
    model.set_logger(Logger(None, []))       # SB3's default makes a folder in /tmp per run
    timer = _rollout_timer()
    t0 = time.perf_counter()
    model.learn(steps, callback=[timer, phase_threads(torch.get_num_threads())],
                progress_bar=False)
    total = time.perf_counter() - t0
    return Throughput(label, n_envs, env_rate, inference, model.num_timesteps / total,
                      timer.rollout_s, total - timer.rollout_s)


def table(rows: list[Throughput]) -> str:
    """A Markdown table of the measurements."""
    lines = ["| configuration | envs | env steps/s (the model's actions) | inference samples/s | "
             "PPO env steps/s | rollout s | update s | update share |",
             "|---|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        lines.append(f"| {r.label} | {r.n_envs} | {r.env_steps_per_s:.0f} | "
                     f"{r.inference_per_s:.0f} | {r.ppo_steps_per_s:.0f} | {r.rollout_s:.1f} | "
                     f"{r.update_s:.1f} | {100 * r.update_share:.0f}% |")
    return "\n".join(lines)
