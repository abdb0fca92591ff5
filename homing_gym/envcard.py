"""Env cards: each registered env's class docstring, written as a Markdown page of the docs.

``python -m homing_gym.envcard docs/envs`` regenerates the pages; a test checks that the
committed pages match the docstrings.
"""

from __future__ import annotations

import sys
import inspect
from pathlib import Path

import gymnasium as gym

import homing_gym
from homing_gym.cli import command_parser


def env_card(env_id: str) -> str:
    """The Markdown env card of a registered env id."""
    spec = gym.spec(env_id)
    module, name = spec.entry_point.split(":")
    cls = getattr(__import__(module, fromlist=[name]), name)
    body = inspect.cleandoc(cls.__doc__)
    header = (f"# {env_id.split('/')[-1]}\n\n"
              f"```python\nimport gymnasium as gym\nimport homing_gym\n\n"
              f"gym.register_envs(homing_gym)\nenv = gym.make(\"{env_id}\")\n```\n\n"
              f"| | |\n|---|---|\n| Entry point | `{spec.entry_point}` |\n"
              f"| Max episode steps | {spec.max_episode_steps} (`gym.make(..., "
              f"max_episode_steps=N)` changes it; `-1` removes the time limit, Gymnasium's "
              f"convention) |\n\n")
    return header + body + "\n"


def card_filename(env_id: str) -> str:
    """``homing_gym/LocalHoming-v0`` -> ``LocalHoming-v0.md``."""
    return env_id.split("/")[-1] + ".md"


def main(argv: list[str] | None = None) -> int:
    parser = command_parser("python -m homing_gym.envcard", __doc__)
    parser.add_argument("out", nargs="?", default="docs/envs", help="output folder")
    args = parser.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    for env_id in homing_gym.ENV_IDS:
        (out / card_filename(env_id)).write_text(env_card(env_id))
        print(f"wrote {out / card_filename(env_id)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
