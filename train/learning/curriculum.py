"""A curriculum on the start distance (and optionally the success radius) of the training
envs (``curriculum`` setting of ``homing-train``).

    curriculum: {start_distance: [[0.15, 0.35], [0.2, 0.6], [0.3, 1.0], [0.3, 1.5]],
                 promote_at: 0.5, window: 200}
    curriculum: {start_distance: [[0.3, 1.5], [0.3, 1.5], [0.3, 1.5]],
                 success_radius: [0.3, 0.2, 0.15], promote_at: 0.5, window: 200}

The training envs start at stage 0's ``(min, max)`` metres from home and, with
``success_radius`` (one radius per stage, metres), count a stop within that stage's radius
as a success. When at least
``promote_at`` of the last ``window`` training episodes finished at the current stage were
successes (``is_success`` of the episode's last step, as SB3's ``Monitor`` records it), every
training env moves to the next stage (``env_method("set_start_distance", ...)``, with the
stage's radius as ``success_radius=`` when there is one, e.g.
:meth:`homing_gym.envs.LocalHomingEnv.set_start_distance`) and the window starts empty.
The evaluation envs are not touched: they keep ``env_kwargs``' ``start_distance`` and
``success_radius``.
The callback that does it is :class:`~homing_train.learning.curriculum_callback.CurriculumCallback`
(apart, so that this module imports without stable-baselines3, as ``train.py`` does).
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any


#: the env method a curriculum calls on every training env
HOOK = "set_start_distance"


def _number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) \
        and math.isfinite(value)


@dataclass(frozen=True)
class CurriculumSettings:
    """``start_distance``: the stages, each ``(min, max)`` metres from home, in order;
    ``promote_at``: success rate in (0, 1] that moves the envs to the next stage;
    ``window``: finished episodes (at least 1) over which that rate is taken;
    ``success_radius``: one success radius per stage (metres), or ``None`` to keep the
    env's own."""

    start_distance: tuple[tuple[float, float], ...]
    promote_at: float = 0.5
    window: int = 200
    success_radius: tuple[float, ...] | None = None

    def stage_kwargs(self, stage: int) -> dict[str, Any]:
        """The keyword arguments of the env hook for ``stage`` beyond its start distance."""
        return {} if self.success_radius is None else {"success_radius": self.success_radius[stage]}

    def as_dict(self) -> dict[str, Any]:
        """The settings as ``from_value`` reads them (JSON-ready)."""
        out = {"start_distance": [list(s) for s in self.start_distance],
               "promote_at": self.promote_at, "window": self.window}
        if self.success_radius is not None:
            out["success_radius"] = list(self.success_radius)
        return out

    @classmethod
    def from_value(cls, value: Mapping[str, Any]) -> "CurriculumSettings":
        """Checked settings from a mapping (as YAML gives them); every problem raises
        ``ValueError`` naming the bad value and what is allowed."""
        if not isinstance(value, Mapping):
            raise ValueError(f"curriculum must be a mapping with keys start_distance, "
                             f"promote_at, window, success_radius, got {value!r}")
        allowed = ("start_distance", "promote_at", "window", "success_radius")
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
        radii = value.get("success_radius")
        if radii is not None and not (
                isinstance(radii, (list, tuple)) and len(radii) == len(stages)
                and all(_number(r) and r > 0 for r in radii)):
            raise ValueError(f"curriculum success_radius must be a list of {len(stages)} "
                             f"positive radii in metres, one per start_distance stage, got "
                             f"{radii!r}")
        return cls(tuple((float(lo), float(hi)) for lo, hi in stages), float(promote_at),
                   window, None if radii is None else tuple(float(r) for r in radii))


def last_stage(path: Path) -> tuple[int, list[dict]]:
    """The stage a run's curriculum file ``path`` reached and its history ((0, []) when
    there is no file)."""
    if not Path(path).is_file():
        return 0, []
    try:
        history = json.loads(Path(path).read_text())["stages"]
        stage = history[-1]["stage"] if history else 0
    except (ValueError, KeyError, TypeError, IndexError) as err:
        raise ValueError(f"{path}: not a curriculum record ({type(err).__name__}: {err}); "
                         f"expected {{\"stages\": [{{\"stage\": N, ...}}, ...]}}") from None
    if not isinstance(stage, int) or isinstance(stage, bool) or stage < 0:
        raise ValueError(f"{path}: stage {stage!r} is not a whole number >= 0")
    return stage, history


def mark_stages(ax, stages: list[dict]) -> None:
    """Dashed lines on ``ax`` (x: env steps, already plotted) where each stage after the
    first began, numbered at the top right of the line; stages closer together than 4% of
    the x range share one label (``"1-5"``, right of the last) instead of printing over
    each other."""
    lo, hi = ax.get_xlim()
    groups: list[list[dict]] = []
    for stage in stages[1:]:
        ax.axvline(stage["from_step"], color="tab:gray", ls="--", lw=1)
        if groups and stage["from_step"] - groups[-1][-1]["from_step"] < 0.04 * (hi - lo):
            groups[-1].append(stage)
        else:
            groups.append([stage])
    for group in groups:
        first, last = group[0]["stage"], group[-1]["stage"]
        ax.annotate(str(first) if first == last else f"{first}-{last}",
                    (group[-1]["from_step"], 1), xycoords=("data", "axes fraction"),
                    xytext=(2, -2), textcoords="offset points", color="tab:gray",
                    va="top", ha="left", fontsize=8)


def stage_key(stages: list[dict]) -> str:
    """One line per stage: ``"stage 2 from 216k: 0.3-1.5 m, radius 0.3 m"``."""
    return "\n".join(f"stage {s['stage']} from {s['from_step'] / 1000:.0f}k: {stage_label(s)}"
                     for s in stages)


def stage_label(stage: dict) -> str:
    """``"0.3-1.5 m"``, with ``", radius 0.2 m"`` when the stage sets one (a
    ``curriculum.json`` stage record)."""
    lo, hi = stage["start_distance"]
    radius = stage.get("success_radius")
    return f"{lo:g}-{hi:g} m" + ("" if radius is None else f", radius {radius:g} m")


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
    ax.set_xlabel("environment steps")
    ax.set_ylabel("training success rate (%)")
    ax.set_ylim(0, 100)
    mark_stages(ax, stages)
    ax.text(0.98, 0.03, stage_key(stages), transform=ax.transAxes, ha="right", va="bottom",
            fontsize=7, color="0.3", bbox={"facecolor": "white", "alpha": 0.8, "lw": 0})
    ax.set_title(f"training episodes (curriculum: {len(stages)} stages)")
