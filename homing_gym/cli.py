"""One shape for every command of the package: ``prog`` named, defaults shown in ``--help``,
plain-text descriptions taken from the module docstring, and ``--import MODULE``.

``--import MODULE`` (repeatable) imports a user's module before any env is made, so that
its ``register_scene(...)`` or ``gym.register(...)`` is visible to the command. The names
are also put in the environment variable :data:`IMPORT_VARIABLE`, which
``homing_gym/__init__`` reads, so that worker processes (spawned evaluation workers,
``SubprocVecEnv``) import them too.
"""

from __future__ import annotations

import argparse
import importlib
import json
import os
import re
import sys
from typing import Any

#: Comma-separated modules that ``import homing_gym`` imports (set by ``--import``).
IMPORT_VARIABLE = "HOMING_GYM_IMPORT"


class HelpFormatter(argparse.ArgumentDefaultsHelpFormatter,
                    argparse.RawDescriptionHelpFormatter):
    """Shows each option's default (also for options without a help text) and keeps the
    description's line breaks."""

    def _format_action(self, action: argparse.Action) -> str:
        if (action.help is None and action.option_strings
                and action.default not in (None, False, argparse.SUPPRESS)):
            action.help = "default: %(default)s"
        return super()._format_action(action)

    def _get_help_string(self, action: argparse.Action) -> str | None:
        if "default" in (action.help or "") or action.default is None:
            return action.help
        return super()._get_help_string(action)


def seed_value(text: str) -> int:
    """``--seed``'s type: an integer >= 0 (what ``reset(seed=...)`` takes)."""
    try:
        seed = int(text)
    except ValueError:
        seed = -1
    if seed < 0:
        raise argparse.ArgumentTypeError(f"a seed is an integer >= 0, got {text!r}")
    return seed


def worker_count(text: str) -> int:
    """``--workers``' type: an integer >= 1."""
    try:
        workers = int(text)
    except ValueError:
        workers = 0
    if workers < 1:
        raise argparse.ArgumentTypeError(f"a number of workers is an integer >= 1, got "
                                         f"{text!r}")
    return workers


def parse_json_kwargs(text: str | None, option: str = "--env-kwargs") -> dict[str, Any]:
    """The JSON object ``text`` given to ``option`` (``{}`` for none); ``ValueError``
    naming the option otherwise."""
    if not text:
        return {}
    try:
        value = json.loads(text)
    except json.JSONDecodeError as err:
        raise ValueError(f"{option} must be a JSON object, e.g. '{{\"success_on\": \"stop\"}}' "
                         f"({err})") from None
    if not isinstance(value, dict):
        raise ValueError(f"{option} must be a JSON object, got {text!r}")
    return value


def add_env_arguments(parser: argparse.ArgumentParser, default_env: str) -> None:
    """The options that pick the world of a command, the same everywhere: ``--env ID``,
    ``--env-kwargs JSON`` and ``--scene SCENE`` (a built-in or ``--import``-registered
    scene name, or ``mesh:PATH``; shorthand for ``"scene"`` in ``--env-kwargs``). Read
    them with :func:`env_kwargs_from_args`."""
    parser.add_argument("--env", default=default_env, help="env id")
    parser.add_argument("--env-kwargs", default=None, metavar="JSON",
                        help="keyword arguments of gym.make, a JSON object, e.g. "
                        "'{\"scene\": \"lab\", \"success_on\": \"stop\"}'")
    parser.add_argument("--scene", default=None, metavar="SCENE",
                        help="the scene: a scene name (also one registered by --import) or "
                        "mesh:PATH; the same as {\"scene\": SCENE} in --env-kwargs")


def env_kwargs_from_args(args: argparse.Namespace) -> dict[str, Any]:
    """``--env-kwargs`` with ``--scene`` in it (:func:`add_env_arguments`); ``ValueError``
    if both name a scene."""
    kwargs = parse_json_kwargs(args.env_kwargs)
    if args.scene is not None:
        if "scene" in kwargs:
            raise ValueError(f"--scene {args.scene!r} and --env-kwargs' scene "
                             f"{kwargs['scene']!r}: give the scene once")
        kwargs["scene"] = args.scene
    return kwargs


def plain(text: str) -> str:
    """reStructuredText markup of a docstring as plain text (````x```` and ``:role:`x```
    become ``x``; ``~a.b`` becomes ``b``)."""
    text = re.sub(r":\w+:`~?([^`]+)`", lambda m: m.group(1).rsplit(".", 1)[-1]
                  if m.group(0).count("~") else m.group(1), text)
    return text.replace("``", "")


def import_user_module(name: str) -> None:
    """Import ``name`` here and, through :data:`IMPORT_VARIABLE`, in worker processes. The
    current folder is searched too (last, so it shadows no installed module), as
    ``python -m`` would: a console script's path lacks it. Spawned workers inherit the
    path."""
    here = os.getcwd()
    if here not in sys.path:
        sys.path.append(here)
    try:
        importlib.import_module(name)
    except ImportError as err:
        raise ValueError(f"--import {name!r}: cannot import it ({err})") from None
    except Exception as err:  # noqa: BLE001  (the user's module: any error is theirs)
        raise ValueError(f"--import {name!r}: importing it failed: "
                         f"{type(err).__name__}: {err}") from None
    listed = [m for m in os.environ.get(IMPORT_VARIABLE, "").split(",") if m]
    if name not in listed:
        os.environ[IMPORT_VARIABLE] = ",".join([*listed, name])


def import_listed_modules() -> None:
    """Import the modules listed in :data:`IMPORT_VARIABLE` (in a worker process)."""
    for name in filter(None, os.environ.get(IMPORT_VARIABLE, "").split(",")):
        importlib.import_module(name)


class _ImportAction(argparse.Action):
    def __call__(self, parser, namespace, value, option_string=None):
        try:
            import_user_module(value)
        except ValueError as err:
            parser.error(str(err))
        getattr(namespace, self.dest).append(value)


def command_parser(prog: str, doc: str | None) -> argparse.ArgumentParser:
    """An argument parser for command ``prog`` whose description is the first paragraph
    of ``doc`` (a module docstring) in plain text, with ``--import MODULE``."""
    first = (doc or "").strip().split("\n\n")[0]
    parser = argparse.ArgumentParser(prog=prog, description=plain(first),
                                     formatter_class=HelpFormatter)
    parser.add_argument("--import", dest="imports", action=_ImportAction, default=[],
                        metavar="MODULE", help="import this module first, e.g. one that "
                        "registers your scene or env id (repeatable; workers import it too)")
    return parser
