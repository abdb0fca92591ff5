"""Pictures of the world families (:mod:`homing_gym.scenes.families`): for each family, a
few worlds seen from above (1 m scale bar, the robot's start in blue) beside the ray-cast
panorama at the start, at that world's camera height, under its sky and light.

``python -m homing_train.figures.families --out docs/images/families`` writes
``NAME.png`` for every family.
"""

from __future__ import annotations

import sys
from pathlib import Path

import imageio.v2 as imageio
import numpy as np

from homing_gym.cli import command_parser
from homing_gym.outputs import output_dir_argument
from homing_gym.scenes.families import FAMILIES
from homing_train.figures.worlds import world_row


def main(argv: list[str] | None = None) -> int:
    parser = command_parser("python -m homing_train.figures.families", __doc__)
    parser.add_argument("--out", type=output_dir_argument, default="docs/images/families",
                        help="output folder")
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2],
                        help="the worlds' seeds")
    parser.add_argument("--families", nargs="+", choices=sorted(FAMILIES),
                        default=sorted(FAMILIES), help="families to draw")
    args = parser.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    for name in args.families:
        rows = [world_row(name, seed, renderers=("raycast",)) for seed in args.seeds]
        imageio.imwrite(out / f"{name}.png", np.concatenate(rows))
        print(f"wrote {out / name}.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
