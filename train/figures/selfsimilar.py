"""Measurements for the self-similar landmarks of Briggs, Scharstein et al. 2000 (issue 8).

    python -m homing_train.figures.selfsimilar speed --out docs/selfsimilar
    python -m homing_train.figures.selfsimilar detection --out docs/selfsimilar
    python -m homing_train.figures.selfsimilar layout --out docs/selfsimilar
    python -m homing_train.figures.selfsimilar nav --runs RUNS --out docs/selfsimilar
    python -m homing_train.figures.selfsimilar memory --runs RUNS --out docs/selfsimilar

``speed``: detector frame rate on one core at 640 x 480 and 320 x 240 (the paper's
sizes), with and without the §3.3 speed-ups (every 2k-th scanline first; peak scan
every l-th pixel), on rendered views of the ``corridors`` scene: one with a landmark at
2 m straight on and one of a bare wall. Writes ``speed.json`` under ``--out`` and prints
a Markdown table beside the paper's 36 and 81 frames/s (450 MHz Pentium II).

``detection``: recall and false positives per image of the detector as the
``selfsimilar`` controller runs it (320 x 240, 60 degrees, w = 22, k = 3) on rendered
views of one panel (id 5) on a wall: over distance (1-5 m) and viewing angle (0-60
degrees off the panel's normal, camera pointed at the panel centre, then turned by
-5, 0 and +5 degrees), over contrast (1, 0.5, 0.25) and over partial occlusion (a dark
board just in front of the panel hiding the left 10, 25 or 50 % of the pattern, from
the self-similarity origin on). A hit: id 5 among the detections; a false positive:
any other detection. Writes ``detection.json`` and ``detection.png`` under ``--out``
and prints Markdown tables.

``layout``: the visibility graph of the ``corridors`` scene as the ``selfsimilar``
controller would find it (§4.1): from each panel's standing place (1 m out along its
normal) a full turn of 12 rendered 320 x 240 views, 30 degrees apart, each searched by
the detector; an edge ``a -> b`` when ``b`` is detected from ``a``'s standing place.
Writes ``layout.json`` (edges, the area of each panel, whether the graph is strongly
connected) and prints the edges.

``nav``: merges the ``homing-eval`` results of ``LandmarkNavigation-v0`` run in chunks
of seeds, ``RUNS/nav_<planning>_<clean|changed>_s<first seed>.json``, into
``nav_<planning>_<clean|changed>.json`` (+ .csv) under ``--out`` and prints the
results table: success with its 95 % bootstrap interval (:func:`homing_train.harness.metrics.bootstrap_ci`),
median path length and shortest path of the successes, steps, collisions.

``memory``: the map kept across episodes against a map per episode. Reads
``RUNS/memory_<planning>_<clean|changed>_<world|episode>.json``, each one ``homing-eval``
run of ``--param memory=world`` or ``episode`` over a sequence of seeds with
``--workers 1`` (one controller, so one map, for the whole sequence), copies them under
``--out`` and prints a table: success, successes per block of 10 episodes of the
sequence, SPL, median path length over the shortest path of the successes, steps.
"""

from __future__ import annotations

import json
import math
import os
import sys
import time
from typing import Sequence

import numpy as np

from homing_baselines.camera_models import PerspectiveModel
from homing_baselines.selfsimilar_detector import DetectorConfig, detect_landmarks
from homing_gym.cli import command_parser
from homing_train.figures import MEASURED_WITH
from homing_gym.outputs import output_dir_argument, save_figure

#: Frames per second reported by the paper (§3.3) with the speed-ups.
PAPER_FPS = {(640, 480): 36.0, (320, 240): 81.0}
#: ... and without them (0.33 s and 0.08 s per image).
PAPER_FPS_PLAIN = {(640, 480): 1 / 0.33, (320, 240): 1 / 0.08}
#: Views of the corridors scene: landmark 9 at 2 m straight on; a bare stretch of wall.
VIEWS = {"landmark": (6.0, 3.0, 0.0), "no landmark": (2.0, 1.2, 0.0)}


def render_views(sizes: Sequence[tuple[int, int]]) -> dict[tuple, np.ndarray]:
    """``{(size, view name): image}`` rendered in the ``corridors`` scene."""
    import gymnasium as gym

    import homing_gym

    gym.register_envs(homing_gym)
    env = gym.make("homing_gym/LandmarkNavigation-v0", **MEASURED_WITH)
    env.reset(seed=0)
    try:
        return {(size, name): env.unwrapped.render_view(pose, size=size, hfov_deg=60)
                for size in sizes for name, pose in VIEWS.items()}
    finally:
        env.close()


def measure_speed(repeats: int = 200) -> list[dict]:
    """Mean detection time per image for every size, view and detector variant."""
    sizes = list(PAPER_FPS)
    images = render_views(sizes)
    variants = {"plain": {}, "speed-ups (2k rows, l = 5)": {"coarse_rows": True,
                                                            "peak_step": 5}}
    rows = []
    for size in sizes:
        model = PerspectiveModel.from_fov(*size, math.radians(60))
        for variant, options in variants.items():
            cfg = DetectorConfig(**options)
            for name in VIEWS:
                image = images[(size, name)]
                found = detect_landmarks(image, model, cfg)          # warm-up
                t0 = time.perf_counter()
                for _ in range(repeats):
                    detect_landmarks(image, model, cfg)
                dt = (time.perf_counter() - t0) / repeats
                rows.append({"size": list(size), "variant": variant, "view": name,
                             "seconds": dt, "fps": 1 / dt,
                             "found": [d.id for d in found]})
    return rows


def speed_table(rows: list[dict]) -> str:
    lines = ["| image | detector | frames/s, landmark in view | frames/s, no landmark | "
             "paper (450 MHz Pentium II) | landmark in view / paper |",
             "|---|---|---:|---:|---:|---:|"]
    keyed = {(tuple(r["size"]), r["variant"], r["view"]): r for r in rows}
    for size in PAPER_FPS:
        for variant in dict.fromkeys(r["variant"] for r in rows):
            a = keyed[(size, variant, "landmark")]
            b = keyed[(size, variant, "no landmark")]
            paper = (PAPER_FPS if "speed" in variant else PAPER_FPS_PLAIN)[size]
            lines.append(f"| {size[0]} x {size[1]} | {variant} | {a['fps']:.0f} | "
                         f"{b['fps']:.0f} | {paper:.0f} | {a['fps'] / paper:.1f}x |")
    return "\n".join(lines)


#: The detector as the controller runs it on its 320 x 240 view.
VIEW_SIZE, VIEW_HFOV = (320, 240), math.radians(60)
VIEW_DETECTOR = DetectorConfig(window=22, row_step=3)
DISTANCES = (1.0, 2.0, 3.0, 4.0, 5.0)
ANGLES = (0, 15, 30, 45, 60)
TURNS = (-5, 0, 5)
CONTRASTS = (1.0, 0.5, 0.25)
OCCLUSIONS = (0.0, 0.1, 0.25, 0.5)
PANEL_ID, PANEL_X = 5, 3.0


def _one_panel_env(contrast: float, occluded: float):
    """LocalHoming-v0 in a 6 m room with panel 5 centred on the wall x = 3 (facing -x),
    of ``contrast``, the left ``occluded`` fraction of its pattern hidden by a board."""
    import gymnasium as gym

    import homing_gym
    from homing_gym.scenes.base import Landmark, Scene, square_walls
    from homing_gym.scenes.corridors import wall_panel
    from homing_gym.selfsimilar import PanelLayout

    gym.register_envs(homing_gym)
    lay = PanelLayout()
    landmarks = [wall_panel(PANEL_ID, PANEL_X, 0.0, math.pi, contrast=contrast)]
    if occluded > 0:
        # as seen from the room the pattern's left edge is at y = width/2 - margin
        y_hi = lay.width / 2
        y_lo = lay.width / 2 - lay.margin - occluded * lay.pattern_width
        landmarks.append(Landmark((PANEL_X - 0.06, (y_hi + y_lo) / 2), shape="box",
                                  extent=(y_hi - y_lo, 0.02), height=0.7,
                                  yaw=math.pi / 2, color=(0.25, 0.25, 0.27, 1.0),
                                  name="occluder"))
    scene = Scene("one_panel", ((-3, -3), (3, 3)), walls=square_walls(6.0, height=1.2),
                  landmarks=tuple(landmarks))
    env = gym.make("homing_gym/LocalHoming-v0", scene=scene, start_distance=(0.3, 1.0),
                   **MEASURED_WITH)
    env.reset(seed=0)
    return env


def _viewpoints(distance: float, angle_deg: float):
    """Poses ``distance`` m from the panel centre, ``angle_deg`` off its normal, facing
    the centre and then turned by each of ``TURNS`` degrees."""
    a = math.radians(angle_deg)
    x, y = PANEL_X - distance * math.cos(a), distance * math.sin(a)
    facing = math.atan2(-y, PANEL_X - x)
    return [np.array([x, y, facing + math.radians(t)]) for t in TURNS]


def measure_detection() -> list[dict]:
    """One row per condition: images, hits, false positives."""
    from homing_baselines.camera_models import PerspectiveModel

    model = PerspectiveModel.from_fov(*VIEW_SIZE, VIEW_HFOV)
    grids = [(1.0, 0.0, DISTANCES, ANGLES)]
    grids += [(c, 0.0, (2.0, 4.0), (0, 30, 60)) for c in CONTRASTS[1:]]
    grids += [(1.0, f, (2.0, 4.0), (0, 30, 60)) for f in OCCLUSIONS[1:]]
    rows = []
    for contrast, occluded, distances, angles in grids:
        env = _one_panel_env(contrast, occluded)
        try:
            for d in distances:
                for a in angles:
                    hits = false = 0
                    for pose in _viewpoints(d, a):
                        image = env.unwrapped.render_view(pose, size=VIEW_SIZE,
                                                          hfov_deg=math.degrees(VIEW_HFOV))
                        ids = [x.id for x in detect_landmarks(image, model, VIEW_DETECTOR)]
                        hits += PANEL_ID in ids
                        false += sum(i != PANEL_ID for i in ids)
                    rows.append({"contrast": contrast, "occluded": occluded, "distance": d,
                                 "angle": a, "images": len(TURNS), "hits": hits,
                                 "false_positives": false})
        finally:
            env.close()
    return rows


def detection_tables(rows: list[dict]) -> str:
    """Recall (hits / images) tables: distance x angle at full contrast; contrast and
    occlusion at 2 and 4 m; and false positives per image overall."""
    def cell(sel):
        n = sum(r["images"] for r in sel)
        return f"{sum(r['hits'] for r in sel)}/{n}" if n else ""

    out = ["Recall, full contrast, no occlusion (hits/images):", "",
           "| distance (m) | " + " | ".join(f"{a} deg" for a in ANGLES) + " |",
           "|---|" + "---:|" * len(ANGLES)]
    base = [r for r in rows if r["contrast"] == 1.0 and r["occluded"] == 0.0]
    for d in DISTANCES:
        out.append(f"| {d:g} | " + " | ".join(
            cell([r for r in base if r["distance"] == d and r["angle"] == a])
            for a in ANGLES) + " |")
    out += ["", "Recall at 2 m / 4 m, over 0, 30 and 60 deg:", "",
            "| condition | 2 m | 4 m |", "|---|---:|---:|"]
    for c in CONTRASTS:
        sel = [r for r in rows if r["contrast"] == c and r["occluded"] == 0.0
               and r["angle"] in (0, 30, 60)]
        out.append(f"| contrast {c:g} | " + " | ".join(
            cell([r for r in sel if r["distance"] == d]) for d in (2.0, 4.0)) + " |")
    for f in OCCLUSIONS[1:]:
        sel = [r for r in rows if r["occluded"] == f]
        out.append(f"| {f:.0%} of the pattern occluded | " + " | ".join(
            cell([r for r in sel if r["distance"] == d]) for d in (2.0, 4.0)) + " |")
    images = sum(r["images"] for r in rows)
    false = sum(r["false_positives"] for r in rows)
    out += ["", f"False positives: {false} in {images} images "
                f"({false / images:.3f} per image)."]
    return "\n".join(out)


def detection_figure(rows: list[dict], path: str) -> None:
    """Recall over distance, one line per viewing angle (full contrast, no occlusion)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5, 3.2))
    for a in ANGLES:
        sel = [r for r in rows if r["contrast"] == 1.0 and r["occluded"] == 0.0
               and r["angle"] == a]
        ax.plot([r["distance"] for r in sel], [r["hits"] / r["images"] for r in sel],
                marker="o", label=f"{a} deg")
    ax.set(xlabel="distance to the panel centre (m)", ylabel="recall", ylim=(-0.05, 1.05),
           title="Detection in the 320 x 240 view (w = 22, k = 3)")
    ax.legend(title="off the normal", fontsize=8)
    fig.tight_layout()
    save_figure(fig, path, dpi=110)
    plt.close(fig)


#: The controller's standing place (m out along a panel's normal) and scan step (degrees).
STANDOFF, SCAN_STEP = 1.0, 30


def panel_area(scene, landmark_id: int) -> int:
    """Index of the room (``scene.metadata["rooms"]``) a panel faces into."""
    x, y, normal = scene.metadata["landmarks"][landmark_id]
    px, py = x + 0.3 * math.cos(normal), y + 0.3 * math.sin(normal)
    for i, ((x0, y0), (x1, y1)) in enumerate(scene.metadata["rooms"]):
        if x0 <= px <= x1 and y0 <= py <= y1:
            return i
    raise ValueError(f"panel {landmark_id} faces no room of scene {scene.name!r}")


def scan_visibility(env) -> dict[int, list[int]]:
    """``{a: ids detected in a full turn from a's standing place}`` in ``env``'s scene
    (a ``LandmarkNavigation-v0`` env after ``reset``), as :data:`VIEW_DETECTOR` sees
    the rendered views."""
    from homing_gym.tasks.landmark_navigation import standing_pose

    u = env.unwrapped
    model = PerspectiveModel.from_fov(*VIEW_SIZE, VIEW_HFOV)
    seen = {}
    for a, panel in sorted(u.scene.metadata["landmarks"].items()):
        x, y, heading = standing_pose(panel, STANDOFF)
        ids: set[int] = set()
        for turn in range(0, 360, SCAN_STEP):
            pose = np.array([x, y, heading + math.radians(turn)])
            image = u.render_view(pose, size=VIEW_SIZE, hfov_deg=math.degrees(VIEW_HFOV))
            ids.update(d.id for d in detect_landmarks(image, model, VIEW_DETECTOR))
        seen[a] = sorted(ids - {a})
    return seen


def measure_layout() -> dict:
    """:func:`scan_visibility` in the ``corridors`` scene, with the areas and whether
    every panel can reach every other one over the edges."""
    import gymnasium as gym
    import networkx as nx

    import homing_gym

    gym.register_envs(homing_gym)
    env = gym.make("homing_gym/LandmarkNavigation-v0", **MEASURED_WITH)
    env.reset(seed=0)
    try:
        seen = scan_visibility(env)
        scene = env.unwrapped.scene
        areas = {a: panel_area(scene, a) for a in seen}
    finally:
        env.close()
    graph = nx.DiGraph([(a, b) for a, bs in seen.items() for b in bs])
    graph.add_nodes_from(seen)
    return {"seen": {str(a): b for a, b in seen.items()},
            "areas": {str(a): i for a, i in areas.items()},
            "strongly_connected": nx.is_strongly_connected(graph)}


PLANNINGS, CONDITIONS = ("deterministic", "probabilistic"), ("clean", "changed")
MEMORIES = ("episode", "world")


def merge_nav_runs(runs: str, out: str) -> dict:
    """Merge the chunks of each planning x condition (see the module docstring); the
    merged result's seed is the smallest chunk's."""
    import glob

    from homing_train.harness.evaluate import EvalResult

    merged = {}
    for planning in PLANNINGS:
        for condition in CONDITIONS:
            paths = glob.glob(os.path.join(runs, f"nav_{planning}_{condition}_s*.json"))
            if not paths:
                continue
            parts = sorted((EvalResult.load(p) for p in paths), key=lambda r: r.seed)
            episodes = [e for r in parts for e in r.episodes]
            result = EvalResult(parts[0].policy, parts[0].params, parts[0].env_id,
                                parts[0].env_kwargs, parts[0].seed, episodes)
            result.save(os.path.join(out, f"nav_{planning}_{condition}.json"))
            merged[(planning, condition)] = result
    return merged


def nav_table(merged: dict) -> str:
    """Markdown table of merged navigation results."""
    lines = ["| planning | landmarks | episodes (seeds) | success % [95% CI] | path length of "
             "successes, median (m) | shortest path of successes, median (m) | steps, median "
             "| collisions, median |", "|---|---|---:|---:|---:|---:|---:|---:|"]
    for (planning, condition), r in merged.items():
        ok = [e for e in r.episodes if e.success]
        seeds = sorted(e.seed for e in r.episodes)
        lo, hi = r.summary["success_ci"]
        path = np.median([e.path_length for e in ok]) if ok else math.nan
        short = np.median([e.shortest_path for e in ok]) if ok else math.nan
        land = ("all, unoccluded" if condition == "clean"
                else "20 % removed, 30 % occluded")
        lines.append(
            f"| {planning} | {land} | {len(seeds)} ({seeds[0]}-{seeds[-1]}) | "
            f"{100 * r.summary['success_rate']:.0f} [{100 * lo:.0f}, {100 * hi:.0f}] | "
            f"{path:.1f} | {short:.1f} | {np.median([e.steps for e in r.episodes]):.0f} | "
            f"{np.median([e.collisions for e in r.episodes]):.0f} |")
    return "\n".join(lines)


def memory_results(runs: str, out: str) -> dict:
    """``{(planning, condition, memory): EvalResult}`` of the runs
    ``runs/memory_<planning>_<condition>_<memory>.json``, each saved under ``out``."""
    from homing_train.harness.evaluate import EvalResult

    results = {}
    for planning in PLANNINGS:
        for condition in CONDITIONS:
            for memory in MEMORIES:
                name = f"memory_{planning}_{condition}_{memory}.json"
                if os.path.exists(os.path.join(runs, name)):
                    result = EvalResult.load(os.path.join(runs, name))
                    result.save(os.path.join(out, name))
                    results[(planning, condition, memory)] = result
    return results


def memory_table(results: dict, block: int = 10) -> str:
    """Markdown table of :func:`memory_results`, one row per planning, condition and
    memory, ordered so that the two memories of a configuration stand together."""
    lines = ["| planning | landmarks | map | episodes (seeds) | success % [95% CI] | "
             f"successes per {block} episodes | SPL | path / shortest, median of successes "
             "| steps, median |", "|---|---|---|---:|---:|---|---:|---:|---:|"]
    for key in sorted(results, key=lambda k: (PLANNINGS.index(k[0]), CONDITIONS.index(k[1]),
                                              MEMORIES.index(k[2]))):
        planning, condition, memory = key
        r = results[key]
        episodes = sorted(r.episodes, key=lambda e: e.seed)
        ok = np.array([e.success for e in episodes])
        blocks = ", ".join(str(int(ok[i:i + block].sum())) for i in range(0, ok.size, block))
        ratio = [e.path_length / e.shortest_path for e in episodes
                 if e.success and e.shortest_path > 0]
        lo, hi = r.summary["success_ci"]
        land = "all, unoccluded" if condition == "clean" else "20 % removed, 30 % occluded"
        kept = "kept across episodes" if memory == "world" else "per episode"
        lines.append(
            f"| {planning} | {land} | {kept} | {ok.size} ({episodes[0].seed}-"
            f"{episodes[-1].seed}) | {100 * ok.mean():.0f} [{100 * lo:.0f}, {100 * hi:.0f}] "
            f"| {blocks} | {r.summary['spl']:.2f} | "
            f"{np.median(ratio) if ratio else math.nan:.2f} | "
            f"{np.median([e.steps for e in episodes]):.0f} |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = command_parser("python -m homing_train.figures.selfsimilar", __doc__)
    parser.add_argument("what", choices=["speed", "detection", "layout", "nav", "memory"])
    parser.add_argument("--runs", help="nav, memory: folder of the homing-eval results")
    parser.add_argument("--out", type=output_dir_argument, default="docs/selfsimilar")
    parser.add_argument("--repeats", type=int, default=200)
    args = parser.parse_args(argv)
    if args.repeats < 1:
        parser.error(f"--repeats must be >= 1, got {args.repeats}")
    os.makedirs(args.out, exist_ok=True)
    if args.what in ("nav", "memory") and not args.runs:
        parser.error(f"{args.what} needs --runs FOLDER")
    runs = {"memory": (memory_results, memory_table, "memory_<planning>_<condition>_<memory>"),
            "nav": (merge_nav_runs, nav_table, "nav_<planning>_<condition>_s<seed>")}
    if args.what in runs:
        collect, table, pattern = runs[args.what]
        results = collect(args.runs, args.out)
        if not results:
            parser.error(f"no {pattern}.json in {args.runs!r}")
        print(table(results))
        return 0
    if args.what == "layout":
        result = measure_layout()
        with open(os.path.join(args.out, "layout.json"), "w") as f:
            json.dump(result, f, indent=1)
        for a, bs in result["seen"].items():
            print(f"{a} (area {result['areas'][a]}) sees {bs}")
        print("strongly connected:", result["strongly_connected"])
        return 0
    if args.what == "detection":
        rows = measure_detection()
        with open(os.path.join(args.out, "detection.json"), "w") as f:
            json.dump(rows, f, indent=1)
        detection_figure(rows, os.path.join(args.out, "detection.png"))
        print(detection_tables(rows))
        return 0
    rows = measure_speed(args.repeats)
    with open(os.path.join(args.out, "speed.json"), "w") as f:
        json.dump(rows, f, indent=1)
    print(speed_table(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
