"""``--vec native``: SB3's view of the native vector env gives DummyVecEnv's episodes."""

import numpy as np
import pytest
from stable_baselines3.common.vec_env import DummyVecEnv

from homing_train.learning.native_vec_env import native_vec_env
from homing_train.learning.train import TrainConfig, make_monitored_env, make_vec

KWARGS = {"scene": "random_rooms", "panorama_shape": [16, 64], "supersampling": 1,
          "action_type": "discrete", "control_period": 0.2, "max_episode_steps": 12,
          "episodes_per_world": 1}


@pytest.mark.parametrize("processes", [1, 2])
def test_native_envs_run_the_episodes_of_monitored_dummy_envs(processes):
    """4 envs, 60 steps of random discrete actions (stops and the step limit end
    episodes): observations, rewards, dones, terminal observations, truncation flags,
    successes and SB3's episode statistics equal DummyVecEnv's over Monitor-wrapped envs."""
    native = native_vec_env("homing_gym/LocalHoming-v0", [KWARGS] * 4, processes=processes)
    dummy = DummyVecEnv([lambda: make_monitored_env("homing_gym/LocalHoming-v0", KWARGS)
                         for _ in range(4)])
    try:
        native.seed(5), dummy.seed(5)
        a, b = native.reset(), dummy.reset()
        assert all(np.array_equal(a[k], b[k]) for k in b)
        ends = 0
        for actions in np.random.default_rng(1).integers(0, 4, (60, 4)):
            (oa, ra, da, ia), (ob, rb, db, ib) = native.step(actions), dummy.step(actions)
            assert all(np.array_equal(oa[k], ob[k]) for k in ob)
            np.testing.assert_allclose(ra, rb, rtol=1e-6)
            np.testing.assert_array_equal(da, db)
            for x, y in zip(ia, ib):
                if "terminal_observation" in y:
                    ends += 1
                    assert all(np.array_equal(x["terminal_observation"][k],
                                              y["terminal_observation"][k]) for k in y["terminal_observation"])
                    assert x["TimeLimit.truncated"] == y["TimeLimit.truncated"]
                    assert x["is_success"] == y["is_success"]
                    assert x["episode"]["l"] == y["episode"]["l"]
                    assert x["episode"]["r"] == pytest.approx(y["episode"]["r"], abs=1e-5)
        assert ends >= 10
    finally:
        native.close()
        dummy.close()



def test_train_makes_native_envs_and_reaches_them_with_env_method():
    """``--vec native --workers 2``: the curriculum's hook reaches the env asked for."""
    config = TrainConfig("homing_gym/LocalHoming-v0", n_envs=3, vec="native", workers=2,
                         env_kwargs={**KWARGS, "scene": ["random_rooms", "random_nature"]})
    env = make_vec(config, 3, seed=0)
    try:
        env.reset()
        assert [s.name for s in env.get_attr("scene")] == ["random_rooms", "random_nature",
                                                           "random_rooms"]
        env.env_method("set_start_distance", (0.2, 0.3), indices=[2])
        assert [t.start_distance for t in env.get_attr("task")][2] == (0.2, 0.3)
        obs = env.step(np.zeros(3, np.int64))[0]
        assert obs["panorama"].shape == (3, 3, 16, 64)       # channel-first, as SB3 wants
    finally:
        env.close()


def test_homing_train_runs_with_the_native_vector_env(tmp_path):
    """``homing-train --vec native --workers 2``: a short run writes its folder and
    records how its envs ran."""
    import json

    import yaml

    from homing_train.learning.train import main

    run = tmp_path / "run"
    assert main(["--timesteps", "128", "--n-envs", "2", "--vec", "native", "--workers", "2",
                 "--env-kwargs", json.dumps({"panorama_shape": [36, 64],
                                             "max_episode_steps": 16}),
                 "--no-progress", "--hp", "n_steps=64", "--hp", "batch_size=32",
                 "--hp", "n_epochs=1", "--hp", "eval_freq=64", "--hp", "eval_episodes=1",
                 "--hp", "checkpoint_freq=64", "--hp", "features_dim=32",
                 "--out", str(run)]) == 0
    config = yaml.safe_load((run / "config.yml").read_text())
    assert (config["vec"], config["workers"]) == ("native", 2)
    assert (run / "model.zip").is_file() and json.loads((run / "summary.json").read_text())[
        "timesteps"] == 128
