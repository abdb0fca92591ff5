"""Env cards: each registered env's class docstring, written as a Markdown page of the docs,
with its argument table written from the code: the env class's own arguments (defaults
from its signature, the rest from its ``ARGUMENTS``) and the env core's
(:func:`homing_gym.config.field_table`).

``python -m homing_gym.envcard docs/envs`` regenerates the pages; a test checks that the
committed pages match the code.
"""

from __future__ import annotations

import dataclasses
import sys
import inspect
from pathlib import Path
from typing import Any

import gymnasium as gym

import homing_gym
from homing_gym.cli import command_parser
from homing_gym.config import Argument, field_table

#: Where the argument table goes in an env card: before this heading, else at the end.
TABLE_BEFORE = "## Version history"


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
    table = argument_table(cls)
    if TABLE_BEFORE in body:
        before, after = body.split(TABLE_BEFORE, 1)
        return header + before + table + "\n" + TABLE_BEFORE + after + "\n"
    return header + body + "\n\n" + table


def arguments(cls: type) -> list[Argument]:
    """The rows of ``cls``'s argument table: its own arguments (described in its
    ``ARGUMENTS``), then the env core's, each with ``cls``'s default where it sets one."""
    params = {name: param for name, param in inspect.signature(cls.__init__).parameters.items()
              if param.kind in (param.POSITIONAL_OR_KEYWORD, param.KEYWORD_ONLY)
              and name != "self"}
    core = {row.name: row for row in field_table()}
    own = getattr(cls, "ARGUMENTS", {})
    missing = sorted(set(params) - set(own) - set(core))
    if missing:
        raise ValueError(f"{cls.__name__}.ARGUMENTS does not describe {missing}")
    rows = [Argument(name, str(params[name].annotation), params[name].default, *own[name])
            for name in params if name in own]
    return rows + [row._replace(default=params[row.name].default) if row.name in params
                   and row.name not in own else row
                   for row in core.values() if row.name not in own]


def _shown(value: Any) -> str:
    """A default as code: numbers with ``:g``, a dataclass instance by its class."""
    if isinstance(value, float):
        return f"{value:g}"
    if isinstance(value, tuple):
        return "(" + ", ".join(_shown(v) for v in value) + ("," if len(value) == 1 else "") + ")"
    if dataclasses.is_dataclass(value):
        return f"{type(value).__name__}()"
    return repr(value)


def argument_table(cls: type) -> str:
    """The Markdown table of ``cls``'s arguments (:func:`arguments`)."""
    def cell(text: str) -> str:
        return text.replace("|", "\\|")

    lines = ["| argument | type | default | allowed | unit | meaning |",
             "|---|---|---|---|---|---|"]
    lines += [f"| `{r.name}` | `{cell(r.type)}` | `{cell(_shown(r.default))}` | "
              f"{cell(r.allowed)} | {r.unit} | {cell(r.meaning)} |" for r in arguments(cls)]
    return "\n".join(lines) + "\n"


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
