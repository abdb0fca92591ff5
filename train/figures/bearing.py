"""Figures for Bekris, Argyros & Kavraki's bearing-only homing laws (issue 5), from the
pure 2-D simulator :mod:`homing_baselines.bearing_sim`.

    python -m homing_train.figures.bearing reachability --out docs/bearing

``reachability`` draws maps like the paper's Fig. 4: a fixed start ``A``, every goal of
a grid painted gray if the law reaches it (basic, complementary, unified), with the
landmarks, the circle ``C^`` through them, the triangle ``T^`` and the wedges ``H^``
marked. Writes ``reachability_<law>.png``, ``reachability.png`` (the three side by side)
and ``reachability.json`` (per-region fractions) under ``--out``, and prints a Markdown
table of the fractions.

    python -m homing_train.figures.bearing starts --out docs/bearing

``starts`` repeats the unified law's map (coarser grid, no figure) from starts in every
region and writes ``starts.json`` and a Markdown table: how much depends on ``A``.

    python -m homing_train.figures.bearing fig10 --out docs/bearing
    python -m homing_train.figures.bearing fig11 --runs 30 --out docs/bearing

From pixels, in PyBullet: the registered controllers ``bearing-basic``,
``bearing-complementary`` and ``bearing`` (unified) in the ``lab`` scene
(``LocalHoming-v0``, ``success_on="stop"``). ``fig10`` is the paper's Fig. 10 experiment:
3 starts in each of ``C^``, ``H^`` and the rest of the plane, goals ``A``, ``C``, ``E``,
three laws (81 runs); a run is a "Fail" when the law does not stop within the step
budget or stops more than ``--fail-cm`` from the goal. ``fig11`` is Fig. 11: the unified
law to each marked position ``A``-``F`` from ``--runs`` seeded random starts; mean and
standard deviation of the final error. Both write JSON and print Markdown tables beside
the paper's numbers.

    python -m homing_train.figures.bearing pixel-reachability --out docs/bearing
    python -m homing_train.figures.bearing longrange --episodes 10 --out docs/bearing

    python -m homing_train.figures.bearing lab-anywhere --episodes 40 --out docs/bearing

``lab-anywhere`` runs the unified law to the env's own homes anywhere in the lab and
asks the 2-D simulator whether each goal is reachable from its start; ``--param`` sets
the controller, ``--panorama-shape ROWS COLUMNS`` the env's panorama.
``pixel-reachability`` is the Fig. 4 map measured from pixels: the three laws from one
start to a coarse grid of goals in the lab (``pixel_reachability.png`` and ``.json``).
``longrange`` runs ``bearing-longrange`` (§3) on seeded ``LongRangeHoming-v0`` episodes
and writes ``longrange.json``.
"""

from __future__ import annotations

import json
import os
import sys
from typing import Sequence

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from tqdm import tqdm  # noqa: E402

from homing_baselines.bearing_laws import LAWS  # noqa: E402
from homing_baselines.bearing_sim import (ReachabilityMap, SimConfig, circumcircle,  # noqa: E402
                                   reachability_map, region)
from homing_gym.cli import command_parser, seed_value, worker_count  # noqa: E402
from homing_train.figures import MEASURED_WITH  # noqa: E402
from homing_train.harness.policies import parse_params  # noqa: E402
from homing_gym.outputs import output_dir_argument, save_figure  # noqa: E402

#: The landmark triangle of the figures (m): scalene, about 2 m a side.
LANDMARKS = np.array([[-1.0, -0.6], [1.2, -0.5], [0.2, 1.1]])
#: The start A (m), in the rest of the plane like most of the paper's Fig. 10 starts.
START = (-3.0, 3.0)
REGIONS = ("T", "C-T", "H", "rest")
REGION_LABELS = {"T": "T̂", "C-T": "Ĉ − T̂", "H": "Ĥ", "rest": "rest of the plane"}
TITLES = {"basic": "(a) basic law", "complementary": "(b) complementary law",
          "unified": "(c) unified law"}


def region_fractions(rmap: ReachabilityMap, band: float = 0.1) -> dict[str, float]:
    """Fraction of the grid goals (or starts) reached in each region of §2, leaving out
    points within ``band`` m of the circle ``C^`` (where the snapshot barely fixes the
    position: all three landmark-goal circles coincide with ``C^`` on it)."""
    gx, gy = np.meshgrid(rmap.xs, rmap.ys)
    pts = np.stack([gx, gy], axis=-1)
    reg = region(rmap.landmarks, pts)
    centre, radius = circumcircle(rmap.landmarks)
    far = np.abs(np.hypot(gx - centre[0], gy - centre[1]) - radius) > band
    out = {}
    for name in REGIONS:
        m = (reg == name) & rmap.valid & far
        out[name] = float(rmap.reached[m].mean()) if m.any() else float("nan")
    return out


def draw_regions(ax, landmarks: np.ndarray, extent: float) -> None:
    """The circle C^ (dashed), the triangle T^, the sides' extensions bounding the wedges
    H^ (dotted) and the landmarks L1-L3."""
    centre, radius = circumcircle(landmarks)
    t = np.linspace(0, 2 * np.pi, 361)
    ax.plot(centre[0] + radius * np.cos(t), centre[1] + radius * np.sin(t), "--",
            color="tab:blue", lw=1.2, label=r"circle $\hat{C}$ through the landmarks")
    tri = np.vstack([landmarks[:3], landmarks[:1]])
    ax.plot(tri[:, 0], tri[:, 1], "-", color="tab:red", lw=1.2, label=r"triangle $\hat{T}$")
    far = 4 * extent
    for j in range(3):
        for i in (j + 1) % 3, (j + 2) % 3:
            d = landmarks[j] - landmarks[i]
            d = d / np.hypot(*d)
            end = landmarks[j] + far * d
            ax.plot([landmarks[j][0], end[0]], [landmarks[j][1], end[1]], ":",
                    color="tab:green", lw=1.2,
                    label=r"sides extended: wedges $\hat{H}$" if (j, i) == (0, 1) else None)
    ax.plot(landmarks[:, 0], landmarks[:, 1], "s", color="black", ms=7)
    for k, (x, y) in enumerate(landmarks):
        ax.annotate(f"L{k + 1}", (x, y), textcoords="offset points", xytext=(6, 6),
                    fontsize=9, weight="bold")
    # Region labels: H^ in the wedge beyond each vertex, away from the centroid.
    centroid = landmarks[:3].mean(axis=0)
    ax.text(*centroid, r"$\hat{T}$", ha="center", va="center", fontsize=9, color="tab:red")
    for j in range(3):
        d = landmarks[j] - centroid
        p = landmarks[j] + 1.3 * d / np.hypot(*d)
        if np.all(np.abs(p) < extent):
            ax.text(*p, r"$\hat{H}$", ha="center", va="center", fontsize=9, color="tab:green")


def plot_map(ax, rmap: ReachabilityMap, title: str) -> None:
    """One Fig. 4 panel: reached grid points gray, the regions and the start/goal."""
    xs, ys = rmap.xs, rmap.ys
    dx = (xs[1] - xs[0]) / 2 if len(xs) > 1 else 0.5
    dy = (ys[1] - ys[0]) / 2 if len(ys) > 1 else 0.5
    ax.imshow(np.where(rmap.reached, 0.62, 1.0), cmap="gray", vmin=0, vmax=1,
              origin="lower", interpolation="nearest",
              extent=(xs[0] - dx, xs[-1] + dx, ys[0] - dy, ys[-1] + dy))
    extent = max(abs(xs[0]), abs(xs[-1]), abs(ys[0]), abs(ys[-1]))
    draw_regions(ax, rmap.landmarks, extent)
    fixed = rmap.start if rmap.vary == "goal" else rmap.goal
    ax.plot(*fixed, "o", color="tab:orange", ms=8, mec="black")
    ax.annotate("A" if rmap.vary == "goal" else "T", fixed, textcoords="offset points",
                xytext=(7, -12), fontsize=10, weight="bold", color="tab:orange")
    ax.set_xlim(xs[0] - dx, xs[-1] + dx)
    ax.set_ylim(ys[0] - dy, ys[-1] + dy)
    ax.set_aspect("equal")
    ax.set_title(title, fontsize=10)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")


def reachability(out: str, grid: int = 81, extent: float = 4.0,
                 start: Sequence[float] = START, config: SimConfig | None = None,
                 progress: bool = True) -> dict[str, dict[str, float]]:
    """Compute and draw the three maps; return the per-region fractions."""
    cfg = config or SimConfig()
    os.makedirs(out, exist_ok=True)
    xs = np.linspace(-extent, extent, grid)
    maps: dict[str, ReachabilityMap] = {}
    for law in LAWS:
        with tqdm(total=cfg.max_steps, desc=f"{law} ({grid}x{grid} goals)", unit="step",
                  disable=not progress, leave=False) as bar:
            maps[law] = reachability_map(LANDMARKS, law, xs, xs, start=start, config=cfg,
                                         progress=bar.update)
    fractions = {law: region_fractions(m) for law, m in maps.items()}
    for law, m in maps.items():
        fig, ax = plt.subplots(figsize=(5.2, 5.2))
        plot_map(ax, m, f"{TITLES[law]}: reached goals gray")
        ax.legend(loc="lower left", fontsize=7, framealpha=0.9)
        fig.tight_layout()
        save_figure(fig, os.path.join(out, f"reachability_{law}.png"), dpi=90)
        plt.close(fig)
    fig, axes = plt.subplots(1, 3, figsize=(14, 5))
    for ax, law in zip(axes, LAWS):
        plot_map(ax, maps[law], TITLES[law])
    axes[0].legend(loc="lower left", fontsize=7, framealpha=0.9)
    fig.suptitle(f"Reachable goals (gray) from A = {tuple(start)}, "
                 f"step {cfg.step} m, success within {cfg.success_radius} m", fontsize=11)
    fig.tight_layout()
    save_figure(fig, os.path.join(out, "reachability.png"), dpi=80)
    plt.close(fig)
    record = {"landmarks": LANDMARKS.tolist(), "start": list(start), "grid": grid,
              "extent": extent, "config": {"step": cfg.step, "max_steps": cfg.max_steps,
                                           "stop_tol": cfg.stop_tol,
                                           "success_radius": cfg.success_radius},
              "fractions": fractions}
    with open(os.path.join(out, "reachability.json"), "w") as f:
        json.dump(record, f, indent=2)
    return fractions


#: Starts of the ``starts`` table (m): T^, C^ - T^, two in H^, two in the rest.
STARTS = [(0.1, 0.0), (0.2, -0.95), (3.0, -3.0), (-2.5, -2.0), (-3.0, 3.0), (0.0, -2.0)]


def starts_table(out: str, grid: int = 41, extent: float = 4.0, law: str = "unified",
                 config: SimConfig | None = None,
                 progress: bool = True) -> dict[str, dict[str, float]]:
    """Per-region fractions of goals reached by ``law`` from each of :data:`STARTS`."""
    cfg = config or SimConfig()
    os.makedirs(out, exist_ok=True)
    xs = np.linspace(-extent, extent, grid)
    table = {}
    for start in tqdm(STARTS, desc=f"{law} from {len(STARTS)} starts", disable=not progress):
        rmap = reachability_map(LANDMARKS, law, xs, xs, start=start, config=cfg)
        name = f"A = {start} ({REGION_LABELS[str(region(LANDMARKS, np.array(start)))]})"
        table[name] = region_fractions(rmap)
    with open(os.path.join(out, "starts.json"), "w") as f:
        json.dump({"law": law, "grid": grid, "extent": extent, "fractions": table}, f,
                  indent=2)
    return table


def markdown_table(fractions: dict[str, dict[str, float]], first: str = "law") -> str:
    """Per-region fractions of reached goals as a Markdown table."""
    lines = [f"| {first} | " + " | ".join(REGION_LABELS[r] for r in REGIONS) + " |",
             "|---|" + "---|" * len(REGIONS)]
    for law, fr in fractions.items():
        lines.append(f"| {law} | " + " | ".join(f"{100 * fr[r]:.1f}%" for r in REGIONS) + " |")
    return "\n".join(lines)


#: Fig. 10 starts (m) in the lab, by kind of start region (checked with ``region``).
FIG10_STARTS = {"C": ((0.3, 0.2), (-0.3, -0.3), (0.5, -1.0)),
                "H": ((-2.3, -2.0), (2.5, -2.0), (0.3, 2.1)),
                "rest": ((-2.0, 2.0), (2.4, 0.4), (0.9, -2.0))}
FIG10_GOALS = ("A", "C", "E")
PIXEL_LAWS = {"basic": "bearing-basic", "complementary": "bearing-complementary",
              "unified": "bearing"}
#: The paper's Fig. 10 (cm; None = "Fail"), rows as in FIG10_STARTS, columns
#: basic A C E, complementary A C E, unified A C E.
PAPER_FIG10 = [
    [3.5, 3.0, None, None, None, 4.5, 1.0, 4.5, 5.5],
    [2.0, 1.0, None, None, None, 5.5, 2.0, 3.5, 8.5],
    [0.0, 1.5, None, None, None, 4.0, 4.0, 3.0, 3.0],
    [3.5, 11.5, None, None, None, 6.0, 2.0, 9.0, 1.5],
    [1.5, 1.5, None, None, None, 2.5, 3.5, 3.0, 6.5],
    [2.5, 2.0, None, None, None, 8.5, 2.0, 3.0, 3.5],
    [2.0, 2.0, None, None, None, 2.5, 1.5, 2.0, 2.0],
    [4.0, 0.0, None, None, None, 9.0, 3.5, 2.0, 5.5],
    [0.5, 5.5, None, None, None, 3.0, 1.5, 3.5, 8.0]]
#: The paper's Fig. 11: mean and standard deviation of the final error (cm).
PAPER_FIG11 = {"A": (1.45, 1.13), "B": (4.65, 2.10), "C": (2.85, 1.41), "D": (2.55, 1.35),
               "E": (3.22, 1.96), "F": (2.28, 1.22)}
GOAL_YAW = 0.5


def lab_run(env, law: str, start: Sequence[float], goal: str | Sequence[float],
            seed: int = 0) -> dict:
    """One pixel run of ``law`` (a key of :data:`PIXEL_LAWS`) in the lab from ``start``
    ``(x, y, yaw)`` to ``goal``, a marked position's name or a point ``(x, y)`` (m):
    final error (cm), stopped, steps."""
    import homing_baselines
    from homing_train.harness.evaluate import run_episode
    from homing_train.harness.rollout import prepare_policy

    controller = homing_baselines.make(PIXEL_LAWS[law])
    prepare_policy(controller, env)
    xy = env.unwrapped.scene.metadata["marked"][goal] if isinstance(goal, str) else goal
    record = run_episode(env, controller, seed, start=start, home=(*xy, GOAL_YAW))
    if not isinstance(goal, str):
        goal = [round(float(v), 3) for v in goal]
    return {"law": law, "start": [round(float(v), 3) for v in start], "goal": goal,
            "error_cm": 100 * record.final_distance, "stopped": record.terminated,
            "steps": record.steps}


def lab_env(max_steps: int):
    """``LocalHoming-v0`` in the lab, ending when the controller stops."""
    import gymnasium as gym

    import homing_gym

    gym.register_envs(homing_gym)
    return gym.make("homing_gym/LocalHoming-v0", scene="lab", success_on="stop",
                    max_episode_steps=max_steps, **MEASURED_WITH)


def _cell(run: dict, fail_cm: float) -> str:
    return f"{run['error_cm']:.1f}" if run["stopped"] and run["error_cm"] <= fail_cm \
        else "Fail"


def fig10(out: str, max_steps: int = 800, fail_cm: float = 20.0,
          progress: bool = True) -> list[dict]:
    """The Fig. 10 experiment from pixels (module docstring); writes ``fig10.json``."""
    from homing_baselines.bearing_sim import region
    from homing_gym.scenes.lab import POSTERS

    triangle = np.array([pos for _, pos in POSTERS.values()])
    for kind, starts in FIG10_STARTS.items():
        for start in starts:
            got = str(region(triangle, np.array(start)))
            if (kind == "C") != (got in ("T", "C-T")) or (kind != "C" and got != kind):
                raise ValueError(f"Fig. 10 start {start} lies in {got}, not in {kind}")
    env = lab_env(max_steps)
    rng = np.random.default_rng(10)
    runs = []
    jobs = [(kind, i, start, law, goal) for kind, starts in FIG10_STARTS.items()
            for i, start in enumerate(starts) for law in PIXEL_LAWS for goal in FIG10_GOALS]
    yaws = {start: float(rng.uniform(-np.pi, np.pi)) for starts in FIG10_STARTS.values()
            for start in starts}
    for kind, i, start, law, goal in tqdm(jobs, desc="Fig. 10 runs", disable=not progress):
        run = lab_run(env, law, (*start, yaws[start]), goal)
        runs.append({"kind": kind, "attempt": i + 1, **run})
    env.close()
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, "fig10.json"), "w") as f:
        json.dump({"max_steps": max_steps, "fail_cm": fail_cm, "goal_yaw": GOAL_YAW,
                   "runs": runs}, f, indent=1)
    return runs


def fig10_table(runs: list[dict], fail_cm: float = 20.0) -> str:
    """Markdown: ours and the paper's value in each cell, ``ours / paper``."""
    cols = [(law, g) for law in PIXEL_LAWS for g in FIG10_GOALS]
    lines = ["| start | " + " | ".join(f"{law} {g}" for law, g in cols) + " |",
             "|---|" + "---|" * len(cols)]
    r = 0
    for kind, starts in FIG10_STARTS.items():
        for i, start in enumerate(starts):
            cells = []
            for c, (law, goal) in enumerate(cols):
                run = next(x for x in runs if x["kind"] == kind and x["attempt"] == i + 1
                           and x["law"] == law and x["goal"] == goal)
                paper = PAPER_FIG10[r][c]
                cells.append(f"{_cell(run, fail_cm)} / {'Fail' if paper is None else paper}")
            lines.append(f"| {REGION_LABELS.get(kind, 'Ĉ')} {i + 1}: {start} | "
                         + " | ".join(cells) + " |")
            r += 1
    return "\n".join(lines)


def fig11(out: str, runs: int = 30, max_steps: int = 800, seed: int = 11,
          progress: bool = True) -> dict[str, dict[str, float]]:
    """Fig. 11 from pixels: the unified law ``runs`` times to each marked position from
    seeded random collision-free starts 0.5-3 m away; writes ``fig11.json``."""
    from homing_train.harness.protocols import marked_goal_starts

    env = lab_env(max_steps)
    marked = list(env.unwrapped.scene.metadata["marked"])
    tasks = marked_goal_starts("lab", runs, seed, GOAL_YAW)
    results: dict[str, list[dict]] = {goal: [] for goal in marked}
    for i, (_, start, _) in enumerate(tqdm(tasks, desc="Fig. 11 runs", disable=not progress)):
        goal = marked[i // runs]
        results[goal].append(lab_run(env, "unified", start, goal))
    env.close()
    summary = {}
    for goal, rs in results.items():
        err = np.array([x["error_cm"] for x in rs])
        stopped = np.array([x["stopped"] for x in rs])
        summary[goal] = {"mean_cm": float(err.mean()), "std_cm": float(err.std()),
                         "median_cm": float(np.median(err)), "stopped": float(stopped.mean())}
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, "fig11.json"), "w") as f:
        json.dump({"runs_per_goal": runs, "max_steps": max_steps, "seed": seed,
                   "summary": summary, "runs": results}, f, indent=1)
    return summary


def fig11_table(summary: dict[str, dict[str, float]]) -> str:
    """Markdown: mean and std of the final error beside the paper's Fig. 11."""
    goals = sorted(summary)
    lines = ["| | " + " | ".join(goals) + " |", "|---|" + "---|" * len(goals),
             "| mean (cm), ours | " + " | ".join(f"{summary[g]['mean_cm']:.2f}" for g in goals)
             + " |",
             "| std (cm), ours | " + " | ".join(f"{summary[g]['std_cm']:.2f}" for g in goals)
             + " |",
             "| stopped, ours | " + " | ".join(f"{100 * summary[g]['stopped']:.0f}%"
                                              for g in goals) + " |",
             "| mean (cm), paper | " + " | ".join(f"{PAPER_FIG11[g][0]:.2f}" for g in goals)
             + " |",
             "| std (cm), paper | " + " | ".join(f"{PAPER_FIG11[g][1]:.2f}" for g in goals)
             + " |"]
    return "\n".join(lines)


#: Start of the pixel reachability maps (m, rad): in the rest of the plane, as the 2-D
#: maps' ``A``.
PIXEL_START = (-2.0, 2.0, -0.8)


def pixel_reachability(out: str, spacing: float = 1.2, max_steps: int = 600,
                       fail_cm: float = 20.0, progress: bool = True) -> dict:
    """Fig. 4-style maps measured in PyBullet from pixels: each law from
    :data:`PIXEL_START` to every goal of a grid ``spacing`` m apart in the lab (goals with
    less than 0.3 m of clearance left out); a goal is reached when the controller stops
    within ``fail_cm``. Writes ``pixel_reachability.json`` and ``.png``; returns the
    per-region fractions of reached goals per law."""
    from homing_gym.scenes.base import clearance
    from homing_gym.scenes.lab import HALF_X, HALF_Y, POSTERS

    env = lab_env(max_steps)
    scene = env.unwrapped.scene
    triangle = np.array([pos for _, pos in POSTERS.values()])
    xs = np.arange(-HALF_X + spacing / 2, HALF_X, spacing)
    ys = np.arange(-HALF_Y + spacing / 2, HALF_Y, spacing)
    goals = [(float(x), float(y)) for y in ys for x in xs if clearance(scene, (x, y)) >= 0.3]
    runs = [lab_run(env, law, PIXEL_START, goal)
            for law in tqdm(PIXEL_LAWS, desc="laws", disable=not progress) for goal in goals]
    env.close()
    for run in runs:
        run["region"] = str(region(triangle, np.array(run["goal"])))
        run["reached"] = bool(run["stopped"] and run["error_cm"] <= fail_cm)
    fractions = {law: {r: float(np.mean([x["reached"] for x in runs
                                          if x["law"] == law and x["region"] == r]))
                       if any(x["region"] == r for x in runs) else float("nan")
                       for r in REGIONS} for law in PIXEL_LAWS}
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.6))
    for ax, law in zip(axes, PIXEL_LAWS):
        draw_regions(ax, triangle, max(HALF_X, HALF_Y))
        for run in (x for x in runs if x["law"] == law):
            ax.plot(*run["goal"], "o" if run["reached"] else "x", ms=9, mew=2,
                    color="0.45" if run["reached"] else "tab:red")
        ax.plot(*PIXEL_START[:2], "o", color="tab:orange", ms=8, mec="black")
        ax.annotate("A", PIXEL_START[:2], textcoords="offset points", xytext=(7, -12),
                    fontsize=10, weight="bold", color="tab:orange")
        ax.set_xlim(-HALF_X, HALF_X)
        ax.set_ylim(-HALF_Y, HALF_Y)
        ax.set_aspect("equal")
        ax.set_title(f"{TITLES[law]}: reached (gray dot) / failed (red x)", fontsize=10)
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
    fig.suptitle(f"From pixels in the lab: goals reached from A = {PIXEL_START[:2]} "
                 f"(stop within {fail_cm:.0f} cm, {max_steps} steps)", fontsize=11)
    fig.tight_layout()
    os.makedirs(out, exist_ok=True)
    save_figure(fig, os.path.join(out, "pixel_reachability.png"), dpi=80)
    plt.close(fig)
    with open(os.path.join(out, "pixel_reachability.json"), "w") as f:
        json.dump({"start": list(PIXEL_START), "spacing": spacing, "max_steps": max_steps,
                   "fail_cm": fail_cm, "fractions": fractions, "runs": runs}, f, indent=1)
    return fractions


def lab_anywhere(out: str, episodes: int = 40, seed: int = 0, max_steps: int = 800,
                 progress: bool = True, params: dict | None = None,
                 panorama_shape: tuple[int, int] | None = None) -> dict:
    """The unified law (``bearing``) in ``LocalHoming-v0`` in the lab with the env's own
    homes (anywhere in the room) and starts (0.3-1.5 m away), seeds ``seed`` ... ``seed +
    episodes - 1``, a success being a stop within the env's 0.15 m. Each episode is also
    run in the 2-D simulator (:func:`simulated`: the lab's landmark points, ideal
    bearings, no walls): the goal is ``reachable`` when the unified law reaches it there,
    and its path is ``path_clear`` when it keeps off the room's walls and furniture.
    ``near_circle``: the home lies within 0.1 m of the circle ``C^``
    (left out of the reachability tables: the snapshot barely fixes the position there);
    ``goal_landmarks``: poster colours seen in the goal panorama (the laws need three).
    ``params``: the controller's parameters other than its defaults; ``panorama_shape``
    ``(rows, columns)``: the env's panorama if not its default. Writes
    ``lab_anywhere.json``; returns the counts."""
    import gymnasium as gym

    import homing_baselines
    import homing_gym
    from homing_baselines.blobs import detect_blobs
    from homing_gym.scenes.lab import POSTERS
    from homing_train.harness.evaluate import run_episode
    from homing_train.harness.rollout import prepare_policy

    gym.register_envs(homing_gym)
    shape = {} if panorama_shape is None else {"panorama_shape": tuple(panorama_shape)}
    env = gym.make("homing_gym/LocalHoming-v0", scene="lab", success_on="stop",
                   max_episode_steps=max_steps, **MEASURED_WITH, **shape)
    triangle = np.array([pos for _, pos in POSTERS.values()])
    centre, radius = circumcircle(triangle)
    scene = env.unwrapped.scene
    body = env.unwrapped.robot_config.body_radius
    controller = homing_baselines.make("bearing", **(params or {}))
    prepare_policy(controller, env)
    runs: list[dict] = []
    for s in tqdm(range(seed, seed + episodes), desc="lab, homes anywhere",
                  disable=not progress):
        record = run_episode(env, controller, s)
        start, home = np.array(record.start_pose[:2]), np.array(record.home_pose[:2])
        goal_view = env.unwrapped.render_panorama(np.array(record.home_pose))
        runs.append({"seed": s, "start": record.start_pose, "home": record.home_pose,
                     "region": str(region(triangle, home)),
                     **simulated(scene, triangle, start, home, body),
                     "near_circle": bool(abs(np.hypot(*(home - centre)) - radius) <= 0.1),
                     "goal_landmarks": len(detect_blobs(goal_view)),
                     "success": record.success, "stopped": record.terminated,
                     "error_cm": round(100 * record.final_distance, 1),
                     "steps": record.steps, "collisions": record.collisions})
        os.makedirs(out, exist_ok=True)
        with open(os.path.join(out, "lab_anywhere.json"), "w") as f:
            json.dump({"seed": seed, "max_steps": max_steps, "params": params or {},
                       "panorama_shape": list(env.unwrapped.camera.config.panorama_shape),
                       "counts": anywhere_counts(runs),
                       "runs": runs}, f, indent=1)
    env.close()
    return anywhere_counts(runs)


def simulated(scene, landmarks: np.ndarray, start, home, body: float) -> dict[str, bool]:
    """The unified law from ``start`` to ``home`` in the 2-D simulator: ``reachable`` (it
    gets there) and ``path_clear`` (its path keeps ``body`` metres from the walls and
    furniture of ``scene``; the landmark columns, which the controllers go round, are
    left out)."""
    import dataclasses

    from homing_baselines.bearing_sim import simulate
    from homing_gym.scenes.base import clearances

    run = simulate(landmarks, start, home)
    room = dataclasses.replace(scene, landmarks=tuple(
        lm for lm in scene.landmarks if not lm.name.startswith("poster")))
    return {"reachable": run.success,
            "path_clear": bool(clearances(room, run.trajectory).min() >= body)}


def anywhere_counts(runs: list[dict]) -> dict[str, int]:
    """Episodes and successes of :func:`lab_anywhere`: all; those the 2-D simulator
    reaches; those of them whose simulated path stays clear of the walls and furniture,
    off the circle's band, with the three landmarks seen from the goal."""
    reach = [r for r in runs if r["reachable"]]
    clear = [r for r in reach if r["path_clear"] and not r["near_circle"]
             and r["goal_landmarks"] == 3]
    return {"episodes": len(runs), "success": sum(r["success"] for r in runs),
            "reachable": len(reach), "success_reachable": sum(r["success"] for r in reach),
            "reachable_clear": len(clear),
            "success_reachable_clear": sum(r["success"] for r in clear)}


_LONGRANGE: dict = {}


def longrange_episode(seed: int, route_length: float = 8.0) -> dict:
    """One ``bearing-longrange`` episode of ``LongRangeHoming-v0`` (the env is made once
    per process): the row of ``longrange.json``."""
    import gymnasium as gym

    import homing_baselines
    import homing_gym
    from homing_train.harness.evaluate import run_episode
    from homing_train.harness.rollout import prepare_policy

    if _LONGRANGE.get("route_length") != route_length:
        gym.register_envs(homing_gym)
        _LONGRANGE.update(route_length=route_length, env=gym.make(
            "homing_gym/LongRangeHoming-v0", route_length=route_length, success_on="stop",
            **MEASURED_WITH))
    env = _LONGRANGE["env"]
    controller = homing_baselines.make("bearing-longrange")
    prepare_policy(controller, env)
    record = run_episode(env, controller, seed)
    outbound = env.unwrapped.task.outbound_steps
    end = np.array(record.trajectory[outbound][:2]) - record.home_pose[:2]
    return {"seed": seed, "success": record.success,
            "final_cm": round(100 * record.final_distance, 1),
            "heading_error_deg": round(record.final_heading_error_deg, 1),
            "homing_from_m": round(float(np.hypot(*end)), 2),
            "steps": record.steps, "outbound_steps": outbound,
            "milestones": len(controller.milestones or []),
            "legs_done": controller.leg, "collisions": record.collisions}


def longrange(out: str, episodes: int = 10, seed: int = 0, route_length: float = 8.0,
              workers: int = 1, progress: bool = True) -> list[dict]:
    """``bearing-longrange`` on ``LongRangeHoming-v0`` (lab, ``success_on="stop"``: a
    success when the controller stops within 0.2 m of home) for the seeds ``seed`` ...
    ``seed + episodes - 1`` over ``workers`` processes; each episode is printed and added
    to ``longrange.json`` (in seed order) as it ends (``homing_from_m``: distance to home
    at the end of the outbound route; a dead worker: see :mod:`homing_train.pool`)."""
    import contextlib
    from functools import partial

    import homing_baselines
    from homing_train.pool import pool_results

    os.makedirs(out, exist_ok=True)
    params = homing_baselines.make("bearing-longrange").params()
    seeds = list(range(seed, seed + episodes))
    run = partial(longrange_episode, route_length=route_length)
    finished = (pool_results(run, seeds, workers, name=lambda s: f"seed {s}") if workers > 1
                else ((i, run(s)) for i, s in enumerate(seeds)))
    rows: dict[int, dict] = {}
    with contextlib.closing(finished):
        for i, row in tqdm(finished, total=episodes, desc="long-range episodes",
                           disable=not progress):
            rows[i] = row
            tqdm.write(json.dumps(row))
            with open(os.path.join(out, "longrange.json"), "w") as f:
                json.dump({"route_length": route_length, "params": params,
                           "episodes": [rows[k] for k in sorted(rows)]}, f, indent=1,
                          default=str)
    return [rows[k] for k in sorted(rows)]


def main(argv: list[str] | None = None) -> int:
    parser = command_parser("python -m homing_train.figures.bearing", __doc__)
    sub = parser.add_subparsers(dest="command", required=True)
    rp = sub.add_parser("reachability", help="Fig. 4-style reachability maps of the three laws")
    rp.add_argument("--out", type=output_dir_argument, default="docs/bearing", help="output folder")
    rp.add_argument("--grid", type=int, default=81, help="grid points per axis")
    rp.add_argument("--extent", type=float, default=4.0, help="half-width of the map (m)")
    rp.add_argument("--start", type=float, nargs=2, default=START, help="start A (m)")
    rp.add_argument("--no-progress", action="store_true")
    sp = sub.add_parser("starts", help="the unified law's per-region reach from several starts")
    sp.add_argument("--out", type=output_dir_argument, default="docs/bearing", help="output folder")
    sp.add_argument("--grid", type=int, default=41, help="grid points per axis")
    sp.add_argument("--no-progress", action="store_true")
    f10 = sub.add_parser("fig10", help="Fig. 10 from pixels in the lab scene (81 runs)")
    f10.add_argument("--out", type=output_dir_argument, default="docs/bearing", help="output folder")
    f10.add_argument("--max-steps", type=int, default=800)
    f10.add_argument("--fail-cm", type=float, default=20.0)
    f10.add_argument("--no-progress", action="store_true")
    f11 = sub.add_parser("fig11", help="Fig. 11 from pixels: unified law to marks A-F")
    f11.add_argument("--out", type=output_dir_argument, default="docs/bearing", help="output folder")
    f11.add_argument("--runs", type=int, default=30, help="runs per marked position")
    f11.add_argument("--max-steps", type=int, default=800)
    f11.add_argument("--seed", type=seed_value, default=11,
                     help="seed of the starts (11: the documented table; others: fresh starts)")
    f11.add_argument("--no-progress", action="store_true")
    pr = sub.add_parser("pixel-reachability",
                        help="reachability of the three laws from pixels in the lab")
    pr.add_argument("--out", type=output_dir_argument, default="docs/bearing", help="output folder")
    pr.add_argument("--spacing", type=float, default=1.2, help="goal grid spacing (m)")
    pr.add_argument("--max-steps", type=int, default=600)
    pr.add_argument("--fail-cm", type=float, default=20.0)
    pr.add_argument("--no-progress", action="store_true")
    la = sub.add_parser("lab-anywhere",
                        help="the unified law in the lab, homes anywhere, with 2-D reachability")
    la.add_argument("--out", type=output_dir_argument, default="docs/bearing", help="output folder")
    la.add_argument("--episodes", type=int, default=40)
    la.add_argument("--seed", type=seed_value, default=0, help="seed of the first episode")
    la.add_argument("--max-steps", type=int, default=800)
    la.add_argument("--param", action="append", metavar="KEY=VALUE",
                    help="a parameter of the bearing controller (repeatable)")
    la.add_argument("--panorama-shape", type=int, nargs=2, metavar=("ROWS", "COLUMNS"),
                    help="the env's panorama (default: the env's own)")
    la.add_argument("--no-progress", action="store_true")
    lr = sub.add_parser("longrange", help="bearing-longrange on LongRangeHoming-v0")
    lr.add_argument("--out", type=output_dir_argument, default="docs/bearing", help="output folder")
    lr.add_argument("--episodes", type=int, default=10)
    lr.add_argument("--seed", type=seed_value, default=0, help="seed of the first episode")
    lr.add_argument("--route-length", type=float, default=8.0, help="outbound route (m)")
    lr.add_argument("--workers", type=worker_count, default=1, help="processes")
    lr.add_argument("--no-progress", action="store_true")
    args = parser.parse_args(argv)
    if args.command == "pixel-reachability":
        fractions = pixel_reachability(args.out, args.spacing, args.max_steps, args.fail_cm,
                                       progress=not args.no_progress)
        print(markdown_table(fractions))
    elif args.command == "longrange":
        rows = longrange(args.out, args.episodes, args.seed, args.route_length, args.workers,
                         progress=not args.no_progress)
        within = sum(r["success"] and r["final_cm"] <= 10 for r in rows)
        print(f"success {sum(r['success'] for r in rows)}/{len(rows)}, "
              f"within 10 cm {within}/{len(rows)}")
    elif args.command == "lab-anywhere":
        counts = lab_anywhere(args.out, args.episodes, args.seed, args.max_steps,
                              progress=not args.no_progress,
                              params=parse_params(args.param, "bearing"),
                              panorama_shape=args.panorama_shape)
        print(json.dumps(counts))
    elif args.command == "fig10":
        runs = fig10(args.out, args.max_steps, args.fail_cm, progress=not args.no_progress)
        print(fig10_table(runs, args.fail_cm))
    elif args.command == "fig11":
        print(fig11_table(fig11(args.out, args.runs, args.max_steps, args.seed,
                                progress=not args.no_progress)))
    elif args.command == "reachability":
        fractions = reachability(args.out, args.grid, args.extent, args.start,
                                 progress=not args.no_progress)
        print(markdown_table(fractions))
    elif args.command == "starts":
        table = starts_table(args.out, args.grid, progress=not args.no_progress)
        print(markdown_table(table, first="start"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
