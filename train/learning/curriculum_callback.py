"""The SB3 callback of the start-distance (and success-radius) curriculum (:mod:`homing_train.learning.curriculum`:
the setting, the stages, the plots)."""

from __future__ import annotations

import json
import math
from collections import deque
from pathlib import Path

from stable_baselines3.common.callbacks import BaseCallback

from homing_train.learning.curriculum import HOOK, CurriculumSettings
from homing_gym.outputs import write_text_atomic


class CurriculumCallback(BaseCallback):
    """Moves the training envs through the stages of ``settings`` (see the module).

    Logs ``curriculum/stage``, ``curriculum/success_rate`` (over the current window) and
    ``curriculum/max_start_distance`` (m) (and ``curriculum/success_radius``, m, when the
    stages set one) with every rollout, and writes the stages
    reached, with the env step of each, to ``path`` (JSON). ``stage``: the stage to start
    from (a resumed run's last one, :func:`last_stage`)."""

    def __init__(self, settings: CurriculumSettings, path: Path, stage: int = 0,
                 history: list[dict] | None = None):
        super().__init__()
        if not 0 <= stage < len(settings.start_distance):
            raise ValueError(f"curriculum stage {stage} does not exist; stages 0 to "
                             f"{len(settings.start_distance) - 1}")
        self.settings = settings
        self.path = Path(path)
        self.stage = stage
        self.history = list(history or [])
        self.outcomes: deque[bool] = deque(maxlen=settings.window)

    @property
    def success_rate(self) -> float:
        """Success rate of the episodes in the current window (nan while empty)."""
        return sum(self.outcomes) / len(self.outcomes) if self.outcomes else math.nan

    def _enter(self, stage: int) -> None:
        self.stage = stage
        self.outcomes.clear()
        extra = self.settings.stage_kwargs(stage)
        self.training_env.env_method(HOOK, self.settings.start_distance[stage], **extra)
        if not self.history or self.history[-1]["stage"] != stage:
            self.history.append({"stage": stage,
                                 "start_distance": list(self.settings.start_distance[stage]),
                                 **extra, "from_step": int(self.num_timesteps)})
        write_text_atomic(self.path, json.dumps({"settings": self.settings.as_dict(),
                                                 "stages": self.history}, indent=2))

    def _on_training_start(self) -> None:
        self._enter(self.stage)

    def _on_step(self) -> bool:
        for info in self.locals["infos"]:
            if "episode" in info:           # Monitor's record of a finished episode
                self.outcomes.append(bool(info["episode"]["is_success"]))
        last = len(self.settings.start_distance) - 1
        if (self.stage < last and len(self.outcomes) == self.settings.window
                and self.success_rate >= self.settings.promote_at):
            self._enter(self.stage + 1)
        return True

    def _on_rollout_end(self) -> None:
        self.logger.record("curriculum/stage", self.stage)
        self.logger.record("curriculum/success_rate", self.success_rate)
        self.logger.record("curriculum/max_start_distance",
                           self.settings.start_distance[self.stage][1])
        for name, value in self.settings.stage_kwargs(self.stage).items():
            self.logger.record(f"curriculum/{name}", value)
