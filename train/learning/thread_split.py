"""Torch threads per phase of PPO: one while it collects rollouts, ``torch_threads`` while
it updates.

During rollouts the learner runs the policy on one small batch per env step while the
env workers share the same cores; torch's second intra-op thread then only spins against
them. Measured on 2 cores (16 envs in 2 workers, a checkpoint of the fast configuration
at its curriculum's stage 3, 16,384 steps each; docs/training.md, "A learner sized for
two cores"): 2 threads throughout 585 PPO env steps/s, 1 thread throughout 523, one
during rollouts and 2 during updates 682.
"""

from __future__ import annotations


def phase_threads(update_threads: int):
    """An SB3 callback that sets torch to 1 thread at each rollout's start and to
    ``update_threads`` at its end (before the update)."""
    import torch
    from stable_baselines3.common.callbacks import BaseCallback

    class PhaseThreads(BaseCallback):
        def _on_rollout_start(self) -> None:
            torch.set_num_threads(1)

        def _on_rollout_end(self) -> None:
            torch.set_num_threads(update_threads)

        def _on_step(self) -> bool:
            return True

    return PhaseThreads()
