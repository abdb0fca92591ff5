"""Env cards: each registered env's class docstring, written as a Markdown page of the docs.

``python -m homing_gym.envcard docs/envs`` regenerates the pages; a test checks that the
committed pages match the docstrings.
"""

from __future__ import annotations

import argparse
import inspect
from pathlib import Path

import gymnasium as gym

import homing_gym


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
              f"| Max episode steps | {spec.max_episode_steps} |\n\n")
    return header + body + "\n"


def card_filename(env_id: str) -> str:
    """``homing_gym/LocalHoming-v0`` -> ``LocalHoming-v0.md``."""
    return env_id.split("/")[-1] + ".md"


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description="write the env cards as Markdown pages")
    parser.add_argument("out", nargs="?", default="docs/envs", help="output folder")
    args = parser.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    for env_id in homing_gym.ENV_IDS:
        (out / card_filename(env_id)).write_text(env_card(env_id))
        print(f"wrote {out / card_filename(env_id)}")


if __name__ == "__main__":
    main()
