"""Saves of a ``homing-train`` run that survive a crash: every model zip and
``evaluations.npz`` is written to a temporary file beside it and renamed over it
(:func:`homing_gym.outputs.atomic_path`), so a kill, a full disk or an error mid-save
leaves the old file whole (or none), never a torn one that ``--resume`` cannot read."""

from __future__ import annotations

from pathlib import Path

from stable_baselines3.common.base_class import BaseAlgorithm
from stable_baselines3.common.callbacks import BaseCallback, CheckpointCallback, EvalCallback

from homing_gym.outputs import atomic_path


def save_model(model: BaseAlgorithm, path: Path) -> None:
    """``model.save`` to ``path`` atomically."""
    with atomic_path(str(path)) as tmp, open(tmp, "wb") as f:
        model.save(f)


class AtomicCheckpointCallback(CheckpointCallback):
    """SB3's ``CheckpointCallback`` (``ppo_<steps>_steps.zip`` every ``save_freq`` calls)
    with atomic saves. The run's PPO has no replay buffer or ``VecNormalize`` to save."""

    def _on_step(self) -> bool:
        if self.n_calls % self.save_freq == 0:
            save_model(self.model, Path(self._checkpoint_path(extension="zip")))
        return True


class _SaveBest(BaseCallback):
    """Called by :class:`AtomicEvalCallback` on a new best mean return: saves the model."""

    def __init__(self, path: Path):
        super().__init__()
        self.path = path

    def _on_step(self) -> bool:
        save_model(self.model, self.path)
        return True


class AtomicEvalCallback(EvalCallback):
    """SB3's ``EvalCallback`` writing ``run/evaluations.npz`` and ``run/best_model.zip``
    atomically (``kwargs``: the other ``EvalCallback`` arguments)."""

    def __init__(self, eval_env, run: Path, **kwargs):
        super().__init__(eval_env, log_path=str(run), best_model_save_path=None,
                         callback_on_new_best=_SaveBest(run / "best_model.zip"), **kwargs)
        self.evaluations_path = run / "evaluations.npz"

    def _on_step(self) -> bool:
        if not (self.eval_freq > 0 and self.n_calls % self.eval_freq == 0):
            return True
        # EvalCallback hands log_path to np.savez, which takes an open file as well
        with atomic_path(str(self.evaluations_path)) as tmp, open(tmp, "wb") as f:
            self.log_path = f
            return super()._on_step()
