"""PyBullet's native chatter stays out of stdout and stderr; real errors stay visible."""

import os
import subprocess
import sys

import pytest

from homing_gym.native_output import native_output_captured

SCRIPT = """
import gymnasium as gym, homing_gym
env = gym.make("homing_gym/LocalHoming-v0")
env.reset(seed=0)
env.step(env.action_space.sample())
env.close()
print("table")
"""


def test_making_and_running_an_env_prints_nothing_of_pybullets():
    out = subprocess.run([sys.executable, "-c", SCRIPT], capture_output=True, text=True,
                         timeout=120, check=True)
    assert out.stdout == "table\n"
    assert "pybullet" not in out.stderr and "argv" not in out.stderr


def test_captured_output_is_replayed_to_stderr_when_the_block_fails(capfd):
    with pytest.raises(RuntimeError, match="boom"):
        with native_output_captured():
            os.write(1, b"native line before the failure\n")
            raise RuntimeError("boom")
    captured = capfd.readouterr()
    assert "native line before the failure" in captured.err
    assert captured.out == ""


def test_output_of_a_successful_block_is_dropped_and_descriptors_restored(capfd):
    with native_output_captured():
        os.write(2, b"chatter\n")
    os.write(1, b"after\n")
    captured = capfd.readouterr()
    assert captured.out == "after\n" and "chatter" not in captured.err
