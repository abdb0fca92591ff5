"""How every method does in worlds no policy was trained on, scene by scene, and where it
fails, from a protocol's matrix folder (``homing-suite --protocols unseen --out DIR``
writes ``DIR/unseen/<method>/``).

``python -m homing_train.figures.generalisation --cells DIR/unseen --out docs/generalisation``
writes ``per_scene.png`` (success with the protocol's stop rule per scene, one bar per
method in its fixed colour, Wilson 95 % intervals, episodes per bar in the legend),
``per_scene.md`` (the same as a table, with a column over all scenes),
``failure_kinds.md`` (each method's failures by kind: stuck against something, out of
time elsewhere, stopped near home, stopped away),
``by_distance.png`` (success against the start's distance from home, every scene's
episodes together) and ``failures.png`` (for each method that failed
at all, its failed episode of the lowest seed in each scene seen from above, labelled
with its final distance: the world rebuilt from the episode's seed, the path in orange,
home in green with the success circle, the end in blue, 1 m scale bar), and where the
worlds' camera heights differ (the world families), ``by_camera_height.md`` (success per
0.1 m of the camera's height above the floor). Nothing is run but the worlds'
construction; the episodes come from the folder.
"""

from __future__ import annotations

import json
import math
import sys
from dataclasses import dataclass
from pathlib import Path

import cv2
import gymnasium as gym
import imageio.v2 as imageio
import numpy as np

import homing_gym  # noqa: F401  (registers the env ids)
from homing_gym.cli import command_parser
from homing_gym.render.topdown import BG, MapCanvas, draw_scale_bar, draw_topdown, labelled
from homing_train.harness.evaluate import EpisodeRecord, EvalResult
from homing_train.harness.matrix import setting_stem
from homing_train.harness.metrics import (FAILURE_KINDS, distance_bins, failure_kind,
                                          wilson_interval)
from homing_train.harness.palette import method_color
from homing_gym.outputs import output_dir_argument, save_figure

#: Map tiles (pixels) of ``failures.png``.
TILE = 220


@dataclass
class SceneResult:
    """One method's result in one setting of a protocol."""

    method: str
    label: str
    result: EvalResult

    @property
    def episodes(self) -> list[EpisodeRecord]:
        return self.result.episodes

    @property
    def successes(self) -> int:
        return sum(e.success for e in self.episodes)


def load_results(cells: Path) -> dict[str, list[SceneResult]]:
    """Every method's per-setting results under a protocol folder (each method's
    ``cell.json`` names its settings), in the settings' order."""
    found = {}
    for cell_file in sorted(cells.glob("*/cell.json")):
        cell = json.loads(cell_file.read_text())
        found[cell["method"]] = [
            SceneResult(cell["method"], label,
                        EvalResult.load(str(cell_file.parent / f"{setting_stem(label)}.json")))
            for label in cell["settings"]]
    if not found:
        raise ValueError(f"no <method>/cell.json under {cells}: give the protocol's folder "
                         f"of a homing-suite --protocols run (e.g. results/unseen)")
    return found


def _rate(successes: int, n: int) -> str:
    """``success % [Wilson 95 % interval] (n)``."""
    lo, hi = wilson_interval(successes, n)
    return f"{100 * successes / n:.0f} [{100 * lo:.0f}, {100 * hi:.0f}] ({n})"


def per_scene_markdown(results: dict[str, list[SceneResult]]) -> str:
    """Success % [Wilson 95 % interval] (episodes) per method and scene, and over all
    scenes (every episode counted once: the scenes weigh as their episode counts)."""
    labels = [r.label for r in next(iter(results.values()))]
    lines = ["| method | " + " | ".join(labels) + " | all |",
             "|---|" + "---:|" * (len(labels) + 1)]
    for method, rows in results.items():
        cells = [_rate(r.successes, len(r.episodes)) for r in rows]
        cells.append(_rate(sum(r.successes for r in rows), sum(len(r.episodes) for r in rows)))
        lines.append(f"| {method} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def failure_kinds_markdown(results: dict[str, list[SceneResult]]) -> str:
    """Per method, its episodes over all scenes by outcome: successes, then its failures
    by kind (:func:`~homing_train.harness.metrics.failure_kind`), each a count."""
    lines = ["| method | episodes | success | " + " | ".join(FAILURE_KINDS) + " |",
             "|---|" + "---:|" * (len(FAILURE_KINDS) + 2)]
    for method, rows in results.items():
        counts = dict.fromkeys(FAILURE_KINDS, 0)
        for row in rows:
            for e in row.episodes:
                if not e.success:
                    counts[failure_kind(e.truncated, e.steps, e.collisions, e.final_distance,
                                        row.result.success_radius)] += 1
        n = sum(len(row.episodes) for row in rows)
        lines.append(f"| {method} | {n} | {sum(r.successes for r in rows)} | "
                     + " | ".join(str(counts[k]) for k in FAILURE_KINDS) + " |")
    return "\n".join(lines)


def by_distance_figure(results: dict[str, list[SceneResult]], path: Path,
                       width: float = 0.3) -> None:
    """Success % against the start's distance from home in ``width`` metre bins
    (:func:`~homing_train.harness.metrics.distance_bins`; every scene's episodes
    together), one line per method in its fixed colour, Wilson 95 % intervals as bands."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.5, 3.6), dpi=150)
    for method, rows in results.items():
        episodes = [e for r in rows for e in r.episodes]
        bins = distance_bins([e.start_distance for e in episodes],
                             [e.success for e in episodes], width)
        x = [(b.lo + b.hi) / 2 for b in bins]
        color = method_color(method)
        ax.plot(x, [100 * b.success_rate for b in bins], "-o", ms=3, color=color,
                label=method)
        ax.fill_between(x, [100 * b.success_ci[0] for b in bins],
                        [100 * b.success_ci[1] for b in bins], color=color, alpha=0.12)
    ax.set_xlabel("start distance from home (m)")
    ax.set_ylabel("success % (stopped within radius)")
    ax.set_ylim(0, 100)
    ax.set_title(f"all settings together, {width:g} m bins, Wilson 95 % intervals", fontsize=8)
    ax.legend(fontsize=7, ncol=2, frameon=False, loc="upper right")
    ax.spines[["top", "right"]].set_visible(False)
    fig.tight_layout()
    save_figure(fig, path, bbox_inches="tight")
    plt.close(fig)


def episode_camera_heights(result: SceneResult, worlds: dict) -> list[float]:
    """The camera's height (metres) in each episode of ``result``: the env of its setting
    reset with the episode's seed (the world rebuilt, the height its appearance's or the
    env's); ``worlds`` caches them by env and seed, for the methods that share episodes."""
    spec = result.result
    key = (spec.env_id, json.dumps(spec.env_kwargs.get("scene")),
           json.dumps(spec.env_kwargs.get("camera_height")))
    heights = worlds.setdefault(key, {})
    todo = [e.seed for e in result.episodes if e.seed not in heights]
    if todo:
        env = gym.make(spec.env_id, **spec.env_kwargs)
        try:
            for seed in todo:
                env.reset(seed=seed)
                heights[seed] = env.unwrapped.camera.camera_height
        finally:
            env.close()
    return [heights[e.seed] for e in result.episodes]


def by_camera_height_markdown(results: dict[str, list[SceneResult]],
                              width: float = 0.1) -> str | None:
    """Success % [Wilson 95 % interval] (episodes) per method by the camera's height in
    ``width`` metre bins (every setting's episodes together); ``None`` when every episode
    had the same height."""
    worlds: dict = {}
    heights = {m: [h for r in rows for h in episode_camera_heights(r, worlds)]
               for m, rows in results.items()}
    if len({round(h, 9) for hs in heights.values() for h in hs}) < 2:
        return None
    edges = sorted({(b.lo, b.hi) for m, rows in results.items()
                    for b in distance_bins(heights[m], [e.success for r in rows
                                                        for e in r.episodes], width)})
    lines = ["| method | " + " | ".join(f"{lo:g}-{hi:g} m" for lo, hi in edges) + " |",
             "|---|" + "---:|" * len(edges)]
    for method, rows in results.items():
        found = {(b.lo, b.hi): b for b in distance_bins(
            heights[method], [e.success for r in rows for e in r.episodes], width)}
        lines.append(f"| {method} | " + " | ".join(
            _rate(round(found[k].success_rate * found[k].n), found[k].n) if k in found else "-"
            for k in edges) + " |")
    return "\n".join(lines)


def per_scene_figure(results: dict[str, list[SceneResult]], path: Path) -> None:
    """Grouped bars: success % per scene, one bar per method, Wilson 95 % intervals."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    labels = [_scene(r.label) for r in next(iter(results.values()))]
    counts = sorted({len(r.episodes) for rows in results.values() for r in rows})
    width = 0.8 / len(results)
    fig, ax = plt.subplots(figsize=(max(7.0, 1.9 * len(labels)), 3.8), dpi=150)
    for k, (method, rows) in enumerate(results.items()):
        x = np.arange(len(rows)) + (k - (len(results) - 1) / 2) * width
        rate = np.array([r.successes / len(r.episodes) for r in rows])
        ci = np.array([wilson_interval(r.successes, len(r.episodes)) for r in rows])
        ax.bar(x, 100 * rate, width, color=method_color(method), label=method)
        ax.errorbar(x, 100 * rate, yerr=100 * np.abs(ci.T - rate), fmt="none",
                    ecolor="0.25", elinewidth=0.8, capsize=1.5)
    ax.set_xticks(np.arange(len(labels)), labels)
    ax.set_ylabel("success % (stopped within radius)")
    ax.set_ylim(0, 100)
    ax.set_title(f"{'/'.join(map(str, counts))} episodes per bar, Wilson 95 % intervals",
                 fontsize=8)
    ax.legend(fontsize=7, ncol=(len(results) + 1) // 2, loc="upper center",
              bbox_to_anchor=(0.5, -0.1), frameon=False)
    ax.spines[["top", "right"]].set_visible(False)
    fig.tight_layout()
    save_figure(fig, path, bbox_inches="tight")
    plt.close(fig)


def _scene(label: str) -> str:
    """A setting's label without the protocol's note (``hallway (held out)`` ->
    ``hallway``)."""
    return label.split(" (")[0]


def failure_tile(result: SceneResult) -> np.ndarray:
    """The method's first failed episode in this setting seen from above (``TILE``
    pixels, 1 m scale bar), or a blank tile saying that none failed."""
    failed = sorted((e for e in result.episodes if not e.success), key=lambda e: e.seed)
    if not failed:
        blank = np.full((TILE, TILE, 3), BG, np.uint8)
        return labelled(blank, f"{_scene(result.label)}: none failed", TILE)
    e = failed[0]
    env = gym.make(result.result.env_id, **result.result.env_kwargs)
    try:
        env.reset(seed=e.seed)
        scene = env.unwrapped.scene
    finally:
        env.close()
    xy = np.asarray(e.trajectory or [e.start_pose[:2]], np.float64)
    move = xy[-1] - xy[-2] if len(xy) > 1 else np.zeros(2)
    yaw = math.atan2(move[1], move[0]) if np.any(move) else e.start_pose[2]
    image = draw_topdown(scene, (*xy[-1], yaw), e.home_pose, xy.tolist(),
                         success_radius=result.result.success_radius, size=TILE)
    draw_scale_bar(image, MapCanvas(scene, TILE), 1.0)
    return labelled(image, f"{_scene(result.label)}: {100 * e.final_distance:.0f} cm", TILE)


def failures_figure(results: dict[str, list[SceneResult]], path: Path) -> None:
    """One row per method that failed anywhere (name on the left), one tile per scene."""
    rows = []
    font, scale = cv2.FONT_HERSHEY_SIMPLEX, 0.5
    width = 12 + max(cv2.getTextSize(m, font, scale, 1)[0][0] for m in results)
    for method, scene_results in results.items():
        if all(r.successes == len(r.episodes) for r in scene_results):
            continue
        tiles = np.concatenate([failure_tile(r) for r in scene_results], axis=1)
        name = np.full((tiles.shape[0], width, 3), BG, np.uint8)
        cv2.putText(name, method, (6, tiles.shape[0] // 2), font, scale,
                    tuple(int(255 * c) for c in method_color(method)), 1, cv2.LINE_AA)
        rows.append(np.concatenate([name, tiles], axis=1))
    imageio.imwrite(path, np.concatenate(rows, axis=0))


def main(argv: list[str] | None = None) -> int:
    parser = command_parser("python -m homing_train.figures.generalisation", __doc__)
    parser.add_argument("--cells", required=True,
                        help="a protocol's folder of a homing-suite --protocols run "
                             "(holds <method>/cell.json)")
    parser.add_argument("--out", type=output_dir_argument, default="docs/generalisation", help="output folder")
    parser.add_argument("--methods", nargs="+",
                        help="methods to show, in this order (default: every one found)")
    args = parser.parse_args(argv)
    try:
        results = load_results(Path(args.cells))
        if args.methods:
            unknown = sorted(set(args.methods) - set(results))
            if unknown:
                raise ValueError(f"no results for {unknown} in {args.cells}; found "
                                 f"{sorted(results)}")
            results = {m: results[m] for m in args.methods}
    except ValueError as err:
        parser.exit(2, f"generalisation: error: {err}\n")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "per_scene.md").write_text(per_scene_markdown(results) + "\n")
    (out / "failure_kinds.md").write_text(failure_kinds_markdown(results) + "\n")
    per_scene_figure(results, out / "per_scene.png")
    by_distance_figure(results, out / "by_distance.png")
    failures_figure(results, out / "failures.png")
    heights = by_camera_height_markdown(results)
    if heights is not None:
        (out / "by_camera_height.md").write_text(heights + "\n")
    print(f"wrote {out}/per_scene.md, failure_kinds.md, per_scene.png, by_distance.png, "
          f"failures.png"
          + (", by_camera_height.md" if heights is not None else ""))
    return 0


if __name__ == "__main__":
    sys.exit(main())
