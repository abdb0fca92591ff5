"""Every command has the same shape: named prog, defaults in --help, main(argv) -> int."""

import importlib

import pytest

from homing_gym.cli import plain

COMMANDS = {
    "homing-eval": "homing_train.harness.evaluate",
    "homing-compare": "homing_train.harness.compare",
    "homing-field": "homing_train.harness.field",
    "homing-suite": "homing_train.harness.suite",
    "homing-demo": "homing_train.harness.demo",
    "homing-train": "homing_train.learning.train",
    "homing-benchmark": "homing_gym.benchmark",
    "python -m homing_train.figures.hong": "homing_train.figures.hong",
    "python -m homing_train.figures.yukim": "homing_train.figures.yukim",
    "python -m homing_train.figures.bearing": "homing_train.figures.bearing",
    "python -m homing_train.figures.selfsimilar": "homing_train.figures.selfsimilar",
    "python -m homing_train.figures.multires": "homing_train.figures.multires",
    "python -m homing_train.figures.renderers": "homing_train.figures.renderers",
    "python -m homing_train.learning.ship": "homing_train.learning.ship",
    "python -m homing_gym.envcard": "homing_gym.envcard",
}


@pytest.mark.parametrize("prog", sorted(COMMANDS))
def test_help_names_the_command_and_shows_defaults(prog, capsys):
    module = importlib.import_module(COMMANDS[prog])
    with pytest.raises(SystemExit) as exit_:
        module.main(["--help"])
    assert exit_.value.code == 0
    text = capsys.readouterr().out
    assert text.startswith(f"usage: {prog}")
    assert "``" not in text and ":mod:" not in text
    if "--seed" in text:
        assert "(default: " in text


def test_plain_drops_rest_markup():
    assert plain("see :mod:`homing_gym.env` and ``x = 1``, :func:`~a.b.c`") == \
        "see homing_gym.env and x = 1, c"
