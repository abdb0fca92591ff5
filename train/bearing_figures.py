"""Figures for Bekris, Argyros & Kavraki's bearing-only homing laws (issue 5), from the
pure 2-D simulator :mod:`baselines.bearing_sim`.

    python -m train.bearing_figures reachability --out docs/bearing

``reachability`` draws maps like the paper's Fig. 4: a fixed start ``A``, every goal of
a grid painted gray if the law reaches it (basic, complementary, unified), with the
landmarks, the circle ``C^`` through them, the triangle ``T^`` and the wedges ``H^``
marked. Writes ``reachability_<law>.png``, ``reachability.png`` (the three side by side)
and ``reachability.json`` (per-region fractions) under ``--out``, and prints a Markdown
table of the fractions.

    python -m train.bearing_figures starts --out docs/bearing

``starts`` repeats the unified law's map (coarser grid, no figure) from starts in every
region and writes ``starts.json`` and a Markdown table: how much depends on ``A``.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from typing import Sequence

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from tqdm import tqdm  # noqa: E402

from baselines.bearing_laws import LAWS  # noqa: E402
from baselines.bearing_sim import (ReachabilityMap, SimConfig, circumcircle,  # noqa: E402
                                   reachability_map, region)

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
        fig.savefig(os.path.join(out, f"reachability_{law}.png"), dpi=90)
        plt.close(fig)
    fig, axes = plt.subplots(1, 3, figsize=(14, 5))
    for ax, law in zip(axes, LAWS):
        plot_map(ax, maps[law], TITLES[law])
    axes[0].legend(loc="lower left", fontsize=7, framealpha=0.9)
    fig.suptitle(f"Reachable goals (gray) from A = {tuple(start)}, "
                 f"step {cfg.step} m, success within {cfg.success_radius} m", fontsize=11)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "reachability.png"), dpi=80)
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


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="bearing-figures", description=__doc__.split("\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    rp = sub.add_parser("reachability", help="Fig. 4-style reachability maps of the three laws")
    rp.add_argument("--out", default="docs/bearing", help="output folder")
    rp.add_argument("--grid", type=int, default=81, help="grid points per axis")
    rp.add_argument("--extent", type=float, default=4.0, help="half-width of the map (m)")
    rp.add_argument("--start", type=float, nargs=2, default=START, help="start A (m)")
    rp.add_argument("--no-progress", action="store_true")
    sp = sub.add_parser("starts", help="the unified law's per-region reach from several starts")
    sp.add_argument("--out", default="docs/bearing", help="output folder")
    sp.add_argument("--grid", type=int, default=41, help="grid points per axis")
    sp.add_argument("--no-progress", action="store_true")
    args = parser.parse_args(argv)
    if args.command == "reachability":
        fractions = reachability(args.out, args.grid, args.extent, args.start,
                                 progress=not args.no_progress)
        print(markdown_table(fractions))
    elif args.command == "starts":
        table = starts_table(args.out, args.grid, progress=not args.no_progress)
        print(markdown_table(table, first="start"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
