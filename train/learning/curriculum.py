"""A curriculum on the start distance of the training envs (``curriculum`` setting of
``homing-train``).

    curriculum: {start_distance: [[0.15, 0.35], [0.2, 0.6], [0.3, 1.0], [0.3, 1.5]],
                 promote_at: 0.5, window: 200}

The training envs start at stage 0's ``(min, max)`` metres from home. When at least
``promote_at`` of the last ``window`` training episodes finished at the current stage were
successes (``is_success`` of the episode's last step, as SB3's ``Monitor`` records it), every
training env moves to the next stage (``env_method("set_start_distance", ...)``, e.g.
:meth:`homing_gym.envs.LocalHomingEnv.set_start_distance`) and the window starts empty.
The evaluation envs are not touched: they keep ``env_kwargs``' ``start_distance``.
"""

from __future__ import annotations

import json
import math
from collections import deque
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from stable_baselines3.common.callbacks import BaseCallback

#: the env method a curriculum calls on every training env
HOOK = "set_start_distance"


def _number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) \
        and math.isfinite(value)


@dataclass(frozen=True)
class CurriculumSettings:
    """``start_distance``: the stages, each ``(min, max)`` metres from home, in order;
    ``promote_at``: success rate in (0, 1] that moves the envs to the next stage;
    ``window``: finished episodes (at least 1) over which that rate is taken."""

    start_distance: tuple[tuple[float, float], ...]
    promote_at: float = 0.5
    window: int = 200

    @classmethod
    def from_value(cls, value: Mapping[str, Any]) -> "CurriculumSettings":
        """Checked settings from a mapping (as YAML gives them); every problem raises
        ``ValueError`` naming the bad value and what is allowed."""
        if not isinstance(value, Mapping):
            raise ValueError(f"curriculum must be a mapping with keys start_distance, "
                             f"promote_at, window, got {value!r}")
        allowed = ("start_distance", "promote_at", "window")
        unknown = sorted(set(value) - set(allowed))
        if unknown:
            raise ValueError(f"unknown curriculum settings {unknown}; allowed: {list(allowed)}")
        stages = value.get("start_distance")
        if not (isinstance(stages, (list, tuple)) and stages and all(
                isinstance(s, (list, tuple)) and len(s) == 2 and all(map(_number, s))
                and 0 <= s[0] <= s[1] for s in stages)):
            raise ValueError(f"curriculum start_distance must be a non-empty list of stages "
                             f"[min, max] in metres with 0 <= min <= max, got {stages!r}")
        promote_at = value.get("promote_at", cls.promote_at)
        if not (_number(promote_at) and 0 < promote_at <= 1):
            raise ValueError(f"curriculum promote_at must be a success rate in (0, 1], got "
                             f"{promote_at!r}")
        window = value.get("window", cls.window)
        if not (isinstance(window, int) and not isinstance(window, bool) and window >= 1):
            raise ValueError(f"curriculum window must be an integer >= 1 (episodes), got "
                             f"{window!r}")
        return cls(tuple((float(lo), float(hi)) for lo, hi in stages), float(promote_at),
                   window)


class CurriculumCallback(BaseCallback):
    """Moves the training envs through the stages of ``settings`` (see the module).

    Logs ``curriculum/stage``, ``curriculum/success_rate`` (over the current window) and
    ``curriculum/max_start_distance`` (m) with every rollout, and writes the stages
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
        self.training_env.env_method(HOOK, self.settings.start_distance[stage])
        if not self.history or self.history[-1]["stage"] != stage:
            self.history.append({"stage": stage,
                                 "start_distance": list(self.settings.start_distance[stage]),
                                 "from_step": int(self.num_timesteps)})
        self.path.write_text(json.dumps({"settings": {
            "start_distance": [list(s) for s in self.settings.start_distance],
            "promote_at": self.settings.promote_at, "window": self.settings.window},
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


def last_stage(path: Path) -> tuple[int, list[dict]]:
    """The stage a run's curriculum file ``path`` reached and its history ((0, []) when
    there is no file)."""
    if not Path(path).is_file():
        return 0, []
    history = json.loads(Path(path).read_text())["stages"]
    return (history[-1]["stage"] if history else 0), history


def mark_stages(ax, stages: list[dict]) -> None:
    """Dashed lines on ``ax`` (x: env steps) where each stage after the first began."""
    for stage in stages[1:]:
        ax.axvline(stage["from_step"], color="tab:gray", ls="--", lw=1)
        lo, hi = stage["start_distance"]
        ax.annotate(f"stage {stage['stage']}: {lo:g}-{hi:g} m", (stage["from_step"], 1),
                    xycoords=("data", "axes fraction"), color="tab:gray", rotation=90,
                    va="top", ha="right", fontsize=8)


def plot_training_success(ax, tb: Path, stages: list[dict]) -> None:
    """Training episodes' success rate over the curriculum's window (``curriculum/
    success_rate`` of the TensorBoard logs in ``tb``, every session) against env steps,
    stages marked."""
    from tensorboard.backend.event_processing.event_accumulator import EventAccumulator

    points = {}
    for events in tb.glob("ppo_*"):
        accumulator = EventAccumulator(str(events), size_guidance={"scalars": 0})
        accumulator.Reload()
        if "curriculum/success_rate" in accumulator.Tags()["scalars"]:
            points.update((e.step, e.value) for e in accumulator.Scalars("curriculum/success_rate"))
    steps = sorted(points)
    ax.plot(steps, [100 * points[s] for s in steps], color="tab:orange")
    mark_stages(ax, stages)
    ax.set_xlabel("environment steps")
    ax.set_ylabel("training success rate (%)")
    ax.set_ylim(0, 100)
    lo, hi = stages[0]["start_distance"]
    ax.set_title(f"training episodes (stage 0: {lo:g}-{hi:g} m)")
