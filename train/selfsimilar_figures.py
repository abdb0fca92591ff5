"""Measurements for the self-similar landmarks of Briggs, Scharstein et al. 2000 (issue 8).

    python -m train.selfsimilar_figures speed --out docs/selfsimilar

``speed``: detector frame rate on one core at 640 x 480 and 320 x 240 (the paper's
sizes), with and without the §3.3 speed-ups (every 2k-th scanline first; peak scan
every l-th pixel), on rendered views of the ``corridors`` scene: one with a landmark at
2 m straight on and one of a bare wall. Writes ``speed.json`` under ``--out`` and prints
a Markdown table beside the paper's 36 and 81 frames/s (450 MHz Pentium II).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
from typing import Sequence

import numpy as np

from baselines.camera_models import PerspectiveModel
from baselines.selfsimilar_detector import DetectorConfig, detect_landmarks

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
    env = gym.make("homing_gym/LandmarkNavigation-v0")
    env.reset(seed=0)
    try:
        return {(size, name): env.unwrapped.render_view(pose, size=size, hfov_deg=60)
                for size in sizes for name, pose in VIEWS.items()}
    finally:
        env.close()


def measure_speed(repeats: int = 20) -> list[dict]:
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
             "paper (450 MHz Pentium II) |", "|---|---|---:|---:|---:|"]
    keyed = {(tuple(r["size"]), r["variant"], r["view"]): r for r in rows}
    for size in PAPER_FPS:
        for variant in dict.fromkeys(r["variant"] for r in rows):
            a = keyed[(size, variant, "landmark")]
            b = keyed[(size, variant, "no landmark")]
            paper = (PAPER_FPS if "speed" in variant else PAPER_FPS_PLAIN)[size]
            lines.append(f"| {size[0]} x {size[1]} | {variant} | {a['fps']:.0f} | "
                         f"{b['fps']:.0f} | {paper:.0f} |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m train.selfsimilar_figures",
                                     description=__doc__.split("\n")[0])
    parser.add_argument("what", choices=["speed"])
    parser.add_argument("--out", default="docs/selfsimilar")
    parser.add_argument("--repeats", type=int, default=20)
    args = parser.parse_args(argv)
    if args.repeats < 1:
        parser.error(f"--repeats must be >= 1, got {args.repeats}")
    os.makedirs(args.out, exist_ok=True)
    rows = measure_speed(args.repeats)
    with open(os.path.join(args.out, "speed.json"), "w") as f:
        json.dump(rows, f, indent=1)
    print(speed_table(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
