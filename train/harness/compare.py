"""Compare evaluation results: a Markdown table with CIs and PNG plots.

Command line (also ``python -m homing_train.harness.compare``)::

    homing-compare results/oracle.json results/random.json --out comparison/

writes ``comparison/table.md``, ``success_vs_distance.png``, ``final_distance.png`` and
``trajectories.png``. Trajectories are read from the result JSONs (every episode stores its
path); the scene of each shown episode is rebuilt with ``env.reset(seed)``.
"""

from __future__ import annotations

import os
import sys
from typing import Sequence

import cv2
import gymnasium as gym
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from homing_gym.cli import command_parser  # noqa: E402
from homing_gym.render.topdown import MapCanvas, draw_pose, draw_scale_bar, draw_scene  # noqa: E402
from homing_train.harness.evaluate import (EvalResult, env_default,  # noqa: E402
                                           success_rule_text)
from homing_train.harness.matrix import episode_seconds  # noqa: E402
from homing_train.harness.palette import (HOME_MARK, START_MARK, method_color,  # noqa: E402
                                          method_color_255)
from homing_gym.outputs import (OutputLock, checked_output_dir,  # noqa: E402
                                output_dir_argument, save_figure, write_text_atomic)



def _ci(summary: dict, key: str, ci_key: str, scale: float = 1.0, fmt: str = ".2f") -> str:
    lo, hi = summary[ci_key]
    return f"{scale * summary[key]:{fmt}} [{scale * lo:{fmt}}, {scale * hi:{fmt}}]"


def markdown_table(results: Sequence[EvalResult]) -> str:
    """One row per method: means with 95% bootstrap CIs."""
    head = ("| method | episodes | success % [95% CI] | SPL | soft-SPL | final distance (cm) "
            "| heading error (deg) | path length (m) | steps | collisions / episode |")
    rows = [head, "|---|" + "---:|" * (head.count("|") - 2)]
    for r in results:
        s = r.summary
        rows.append(
            f"| {r.policy} | {s['episodes']} | {_ci(s, 'success_rate', 'success_ci', 100, '.1f')} "
            f"| {_ci(s, 'spl', 'spl_ci', fmt='.3f')} | {_ci(s, 'soft_spl', 'soft_spl_ci', fmt='.3f')} "
            f"| {_ci(s, 'final_distance_mean', 'final_distance_ci', 100, '.1f')} "
            f"| {_ci(s, 'heading_error_deg_mean', 'heading_error_deg_ci', fmt='.1f')} "
            f"| {_ci(s, 'path_length_mean', 'path_length_ci')} "
            f"| {_ci(s, 'steps_mean', 'steps_ci', fmt='.0f')} "
            f"| {_ci(s, 'collisions_mean', 'collisions_ci')} |")
    return "\n".join(rows) + "\n"


def route_table(results: Sequence[EvalResult]) -> str:
    """For the results with route episodes (RouteFollowing-v0), one row each: the share
    of targets reached in order, of routes with every target reached in order
    (``reached_rate``) and with every target left within the radius, targets finished
    per route and the mean error at the targets left; "" for no such result."""
    routes = [r for r in results if "route_episodes" in r.summary]
    if not routes:
        return ""
    head = ("| method | routes | targets reached in order % [95% CI] | every target reached "
            "% [95% CI] | all targets within radius % [95% CI] | targets finished / route "
            "| target error (cm) |")
    rows = [head, "|---|" + "---:|" * (head.count("|") - 2)]
    for r in routes:
        s = r.summary
        error = "-" if s["target_error_mean"] is None else f"{100 * s['target_error_mean']:.1f}"
        within = _ci(s, "all_targets_within_radius_rate", "all_targets_within_radius_ci", 100,
                     ".1f")
        rows.append(
            f"| {r.policy} | {s['route_episodes']} "
            f"| {_ci(s, 'targets_reached_fraction', 'targets_reached_fraction_ci', 100, '.1f')} "
            f"| {_ci(s, 'reached_rate', 'reached_ci', 100, '.1f')} "
            f"| {within} "
            f"| {s['targets_finished_mean']:.1f} | {error} |")
    return "\n".join(rows) + "\n"


#: Env settings that never change an episode (what a controller reads), left out when
#: rows are compared.
NEUTRAL_KEYS = ("obs_keys",)


def success_rule(result: EvalResult) -> tuple:
    """``(env id, success_on, success_radius)`` a result was scored under: its env kwargs,
    else the env's defaults (``None`` where the env has no such argument)."""
    return (result.env_id, *(result.env_kwargs.get(key, env_default(result.env_id, key))
                             for key in ("success_on", "success_radius")))


def rule_line(result: EvalResult) -> str:
    """The line of ``table.md`` that states the success rule of every row (one rule:
    :func:`check_one_rule`)."""
    env, on, radius = success_rule(result)
    within = f" within {radius:g} m" if radius is not None else ""
    return (f"Success rule: {env.split('/')[-1]}, success_on={on!r} ("
            f"{success_rule_text(on)}{within}).\n")


def check_one_rule(results: Sequence[EvalResult]) -> None:
    """``ValueError`` naming each row's rule if the results were not all scored by one
    success rule (the same env, ``success_on`` and ``success_radius``)."""
    rules = [(r.policy, success_rule(r)) for r in results]
    if len({rule for _, rule in rules}) > 1:
        raise ValueError("the results were scored under different success rules, so their "
                         "success rates do not compare: " + "; ".join(
                             f"{name}: {env}, success_on={on!r}, success_radius={radius!r}"
                             for name, (env, on, radius) in rules)
                         + " (homing-suite --success-on gives every row one rule)")


def settings_notes(results: Sequence[EvalResult]) -> list[str]:
    """Lines saying where the rows' envs differ: the renderer, the time an episode may
    last (:func:`~homing_train.harness.matrix.episode_seconds`), and the settings of rows
    that depart from the most common ones (a shipped policy's own, by design)."""
    notes = []
    renderers: dict[str, list[str]] = {}
    for r in results:
        renderers.setdefault(str(r.env_kwargs.get("renderer", "?")), []).append(r.policy)
    if len(renderers) > 1:
        notes.append("rows differ in renderer: " + "; ".join(
            f"{name} ({', '.join(rows)})" for name, rows in renderers.items()))
    times: dict[str, list[str]] = {}
    for r in results:
        seconds = episode_seconds(r.env_id, r.env_kwargs)
        times.setdefault("no limit" if seconds is None else f"{seconds:g} s", []).append(r.policy)
    if len(times) > 1:
        notes.append("rows differ in time per episode: " + "; ".join(
            f"{name} ({', '.join(rows)})" for name, rows in times.items()))
    def key(r: EvalResult) -> str:
        return repr((r.env_id, sorted((k, v) for k, v in r.env_kwargs.items()
                                      if k not in NEUTRAL_KEYS)))
    counts: dict[str, int] = {}
    for r in results:
        counts[key(r)] = counts.get(key(r), 0) + 1
    common = max(counts, key=counts.get)
    reference = next(r for r in results if key(r) == common)
    for r in results:
        if key(r) != common:
            changed = sorted(k for k in set(r.env_kwargs) | set(reference.env_kwargs)
                             if k not in NEUTRAL_KEYS
                             and r.env_kwargs.get(k) != reference.env_kwargs.get(k))
            where = f"{r.env_id}, " if r.env_id != reference.env_id else ""
            notes.append(f"{r.policy} runs with other env settings: {where}"
                         + ", ".join(f"{k}={r.env_kwargs.get(k)!r}" for k in changed))
    return notes


def shared_seeds(results: Sequence[EvalResult]) -> tuple[list[int], str | None]:
    """Seeds present in every result (the paired episodes), and a note when the results
    cover different seeds."""
    seeds = [set(e.seed for e in r.episodes) for r in results]
    shared = sorted(set.intersection(*seeds))
    if any(s != seeds[0] for s in seeds):
        return shared, (f"the results cover different episode seeds, {len(shared)} shared: "
                        f"the rows are not paired episode by episode")
    return shared, None


def _finish(fig, ax, title: str, path: str) -> None:
    """Title, grid, the legend outside the data; save and close."""
    ax.set_title(title, fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=8, frameon=False)
    fig.tight_layout()
    save_figure(fig, path)
    plt.close(fig)


def plot_success_vs_distance(results: Sequence[EvalResult], path: str) -> None:
    """Success rate against start distance, one line per method in its fixed colour,
    95% Wilson intervals as bands, the number of episodes per bin written under it."""
    fig, ax = plt.subplots(figsize=(7.0, 3.8), dpi=110)
    for r in results:
        bins = r.summary["success_by_distance"]
        x = np.array([100 * (b["lo"] + b["hi"]) / 2 for b in bins])
        y = np.array([100 * b["success_rate"] for b in bins])
        lo, hi = np.array([b["success_ci"] for b in bins]).T * 100
        color = method_color(r.policy)
        ax.plot(x, y, marker="o", color=color, label=r.policy)
        ax.fill_between(x, lo, hi, color=color, alpha=0.12, lw=0)
    first = results[0].summary["success_by_distance"]
    for b in first:
        ax.annotate(f"n={b['n']}", (100 * (b["lo"] + b["hi"]) / 2, -9), ha="center",
                    fontsize=7, color="0.35", annotation_clip=False)
    ax.set_xlabel("start distance from home (cm); n = episodes per bin")
    ax.set_ylabel("success rate (%)")
    ax.set_ylim(-3, 103)
    _finish(fig, ax, "Success by start distance (bands: 95% Wilson intervals)", path)


def plot_final_distance(results: Sequence[EvalResult], path: str) -> None:
    """Empirical CDF of the final distance to home, one line per method."""
    fig, ax = plt.subplots(figsize=(7.0, 3.8), dpi=110)
    for r in results:
        d = np.sort([100 * e.final_distance for e in r.episodes])
        ax.step(d, np.arange(1, d.size + 1) / d.size, where="post",
                color=method_color(r.policy), label=f"{r.policy} (n={d.size})")
    radius = results[0].env_kwargs.get("success_radius", 0.15)
    ax.axvline(100 * radius, color="grey", ls="--", lw=1, label="success radius")
    ax.set_xlabel("final distance to home (cm)")
    ax.set_ylabel("fraction of episodes")
    _finish(fig, ax, "Final distance to home (empirical CDF)", path)


def plot_trajectories(results: Sequence[EvalResult], seeds: Sequence[int], path: str,
                      size: int = 300) -> None:
    """Top-down maps of the episodes ``seeds``: every method's path in its colour, home
    and start as rings, a scale bar."""
    first = results[0]
    env = gym.make(first.env_id, **first.env_kwargs)
    panels = []
    try:
        for seed in seeds:
            env.reset(seed=seed)
            scene = env.unwrapped.scene
            canvas = MapCanvas(scene, size)
            img = draw_scene(scene, canvas)
            for r in results:
                episode = next(e for e in r.episodes if e.seed == seed)
                pts = np.array([canvas.px(x, y) for x, y in episode.trajectory], np.int32)
                cv2.polylines(img, [pts], False, method_color_255(r.policy), 2, cv2.LINE_AA)
            shown = next(e for e in first.episodes if e.seed == seed)
            radius = env.unwrapped.robot_config.body_radius
            draw_pose(img, canvas, shown.home_pose, radius, HOME_MARK, filled=False)
            draw_pose(img, canvas, shown.start_pose, radius, START_MARK, filled=False)
            draw_scale_bar(img, canvas)
            panels.append((seed, img))
    finally:
        env.close()
    cols = min(len(panels), 3)
    rows = (len(panels) + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(3.2 * cols, 3.2 * rows + 0.7), dpi=90,
                             squeeze=False)
    for ax in axes.flat:
        ax.axis("off")
    for ax, (seed, img) in zip(axes.flat, panels):
        ax.imshow(img)
        ax.set_title(f"episode seed {seed}", fontsize=9)
    handles = [plt.Line2D([], [], color=method_color(r.policy), lw=2, label=r.policy)
               for r in results]
    handles += [plt.Line2D([], [], color=np.array(HOME_MARK) / 255, marker="o", ls="",
                           mfc="none", label="home"),
                plt.Line2D([], [], color=np.array(START_MARK) / 255, marker="o", ls="",
                           mfc="none", label="start")]
    fig.legend(handles=handles, loc="lower center", ncol=min(len(handles), 5), fontsize=8,
               frameon=False)
    fig.tight_layout(rect=(0, 0.12 if len(handles) > 5 else 0.07, 1, 1))
    save_figure(fig, path)
    plt.close(fig)


def compare(paths: Sequence[str], out: str, trajectories: int = 3) -> dict[str, str]:
    """Write the table and plots for the result files ``paths`` into ``out``; returns
    the written file paths by kind."""
    if not paths:
        raise ValueError("give at least one result JSON")
    if trajectories < 0:
        raise ValueError(f"trajectories must be >= 0 (0: no map), got {trajectories}")
    checked_output_dir(out)
    results = [EvalResult.load(p) for p in paths]
    check_one_rule(results)
    shared, unpaired = shared_seeds(results)
    os.makedirs(out, exist_ok=True)
    written = {"table": os.path.join(out, "table.md"),
               "success_vs_distance": os.path.join(out, "success_vs_distance.png"),
               "final_distance": os.path.join(out, "final_distance.png")}
    routes = route_table(results)
    notes = settings_notes(results) + ([unpaired] if unpaired else [])
    write_text_atomic(written["table"], rule_line(results[0]) + "\n" + markdown_table(results)
                      + ("\n" + routes if routes else "")
                      + ("\n" + "".join(f"Note: {n}.\n" for n in notes) if notes else ""))
    plot_success_vs_distance(results, written["success_vs_distance"])
    plot_final_distance(results, written["final_distance"])
    if trajectories > 0 and shared:
        written["trajectories"] = os.path.join(out, "trajectories.png")
        plot_trajectories(results, shared[:trajectories], written["trajectories"])
    return written


def main(argv: list[str] | None = None) -> int:
    parser = command_parser("homing-compare", __doc__)
    parser.add_argument("results", nargs="+", help="result JSON files of homing-eval")
    parser.add_argument("--out", required=True, type=output_dir_argument,
                        help="output directory")
    parser.add_argument("--trajectories", type=int, default=3,
                        help="number of shared episodes drawn on the top-down map")
    args = parser.parse_args(argv)
    try:
        with OutputLock(args.out):
            written = compare(args.results, args.out, args.trajectories)
    except ValueError as err:
        parser.exit(2, f"homing-compare: error: {err}\n")
    with open(written["table"]) as f:
        print(f.read())
    print("wrote " + ", ".join(written.values()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
