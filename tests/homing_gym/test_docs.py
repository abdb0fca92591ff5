"""The committed env cards in docs/ match the env docstrings."""

from pathlib import Path

import pytest

import homing_gym
from homing_gym.envcard import card_filename, env_card

DOCS = Path(__file__).resolve().parents[2] / "docs" / "envs"


@pytest.mark.parametrize("env_id", homing_gym.ENV_IDS)
def test_env_card_is_current(env_id):
    page = DOCS / card_filename(env_id)
    assert page.is_file(), f"run: python -m homing_gym.envcard docs/envs"
    assert page.read_text() == env_card(env_id), "run: python -m homing_gym.envcard docs/envs"
    for section in ("## Action space", "## Observation space", "## Rewards",
                    "## Starting state", "## Episode end", "## Arguments", "## Version history"):
        assert section in page.read_text()
