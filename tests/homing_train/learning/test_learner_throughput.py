"""The learner benchmark: free envs of a policy's spaces, and the rates derived from one run."""

import subprocess
import sys
import tempfile
from importlib import resources

import numpy as np
import pytest
from gymnasium import spaces

from homing_train.learning.learner_throughput import FreeVecEnv, main, measure_learner

SHIPPED = str(resources.files("homing_train") / "shipped" / "ppo_procedural_long.zip")


def test_free_envs_serve_observations_of_the_spaces_and_end_episodes_on_time():
    obs_space = spaces.Dict({"panorama": spaces.Box(0, 255, (3, 4, 8), np.uint8),
                             "odometry": spaces.Box(-1.0, 1.0, (3,), np.float32)})
    env = FreeVecEnv(3, obs_space, spaces.Discrete(4), episode_steps=5)
    obs = env.reset()
    assert obs["panorama"].shape == (3, 3, 4, 8) and obs["panorama"].dtype == np.uint8
    assert obs["odometry"].shape == (3, 3)
    done_at = []
    for t in range(1, 11):
        obs, rewards, dones, infos = env.step(np.zeros(3, int))
        assert obs_space.contains({k: v[0] for k, v in obs.items()})
        assert rewards.shape == (3,) and not rewards.any()
        if dones.all():
            done_at.append(t)
        else:
            assert not dones.any()
    assert done_at == [5, 10]


def test_measured_rates_follow_from_the_timed_run(tmp_path, monkeypatch):
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))     # where SB3 would log
    row = measure_learner(SHIPPED, "cpu", n_envs=2, n_steps=16, batch_size=16, n_epochs=2,
                          steps=64)
    assert row.timesteps == 64                       # two rollouts of 16 x 2
    r = row.rates
    assert min(r.inference_per_s, r.ppo_steps_per_s, r.rollout_s, r.update_s) > 0
    assert r.ppo_steps_per_s == pytest.approx(64 / (r.rollout_s + r.update_s))
    assert row.update_samples_per_s == pytest.approx(64 * 2 / r.update_s)
    assert row.update_cap == pytest.approx(64 / r.update_s)
    assert not [p for p in tmp_path.iterdir() if p.name.startswith("SB3-")]  # no log folders


def test_bad_settings_are_refused(capsys):
    with pytest.raises(ValueError, match="at least 1"):
        measure_learner(SHIPPED, "cpu", n_envs=0, n_steps=16, batch_size=16, n_epochs=1,
                        steps=16)
    with pytest.raises(ValueError, match="not a torch device"):
        measure_learner(SHIPPED, "gpu0", n_envs=1, n_steps=16, batch_size=16, n_epochs=1,
                        steps=16)
    with pytest.raises(SystemExit):
        main(["--policy", SHIPPED, "--n-envs", "1", "--batch-size", "512"])
    assert "larger than a rollout" in capsys.readouterr().err


def test_the_benchmark_runs_without_pybullet_or_the_envs():
    """It is meant for a GPU machine where only torch and SB3 are installed."""
    code = ("import sys; from homing_train.learning.learner_throughput import measure_learner; "
            f"measure_learner({SHIPPED!r}, 'cpu', 1, 8, 8, 1, 8); "
            "print('pybullet' in sys.modules, 'homing_gym' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["False", "False"]
