"""One shape for every command of the package: ``prog`` named, defaults shown in ``--help``,
plain-text descriptions taken from the module docstring."""

from __future__ import annotations

import argparse
import re


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


def plain(text: str) -> str:
    """reStructuredText markup of a docstring as plain text (````x```` and ``:role:`x```
    become ``x``; ``~a.b`` becomes ``b``)."""
    text = re.sub(r":\w+:`~?([^`]+)`", lambda m: m.group(1).rsplit(".", 1)[-1]
                  if m.group(0).count("~") else m.group(1), text)
    return text.replace("``", "")


def command_parser(prog: str, doc: str | None) -> argparse.ArgumentParser:
    """An argument parser for command ``prog`` whose description is the first paragraph
    of ``doc`` (a module docstring) in plain text."""
    first = (doc or "").strip().split("\n\n")[0]
    return argparse.ArgumentParser(prog=prog, description=plain(first),
                                   formatter_class=HelpFormatter)
