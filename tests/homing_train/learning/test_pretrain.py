"""Behaviour cloning on rendered pose pairs (train/learning/pretrain.py)."""

from __future__ import annotations

import json
import math

import gymnasium as gym
import numpy as np
import pytest

import homing_baselines
from homing_baselines.motion import FORWARD, LEFT, RIGHT, MotionHelper
from homing_gym.geometry import wrap_angle
from homing_train.harness.rollout import prepare_policy
from homing_train.learning.pretrain import pair_labels, pair_samples, pair_set, render_bank, rolled
from homing_train.learning.train import main

KWARGS = {"scene": "arena", "panorama_shape": [16, 64], "action_type": "discrete",
          "control_period": 0.2}


@pytest.fixture(scope="module")
def env():
    env = gym.make("homing_gym/LocalHoming-v0", **KWARGS)
    yield env
    env.close()


def test_turning_rolls_the_panorama_towards_higher_columns(env):
    """The bank's premise: the panorama at heading k columns is the heading-0 panorama
    rolled by +k columns, up to resampling; rolling the other way is far off."""
    u = env.unwrapped
    env.reset(seed=0)
    width = KWARGS["panorama_shape"][1]
    pose = np.array([0.0, 0.9, 0.0])
    u.sim.robot.set_pose(*pose)
    base = u.render_panorama(pose)
    for k in (5, -9, 20):
        turned = pose + [0.0, 0.0, k * 2 * math.pi / width]
        u.sim.robot.set_pose(*turned)
        view = u.render_panorama(turned).astype(float)
        good = np.abs(rolled(base[None], np.array([k]))[0] - view).mean()
        bad = np.abs(rolled(base[None], np.array([-k]))[0] - view).mean()
        assert good < 4.0 and bad > 4 * good, (k, good, bad)


def test_pair_labels_turn_towards_the_oracle_waypoint(env):
    """A label is the oracle's first action: forward when its waypoint lies within half a
    turn step of the heading, else a turn towards it (counter-clockwise: left)."""
    oracle = homing_baselines.make("oracle")
    prepare_policy(oracle, env)
    helper = MotionHelper(oracle.motion_spec, oracle.motion)
    bank = render_bank(env, 12, 1, seed=3, progress=False)
    rng = np.random.default_rng(0)
    pairs = pair_set(bank, 30, (0.15, 1.5), oracle, rng, 0.22, progress=False)
    d = np.linalg.norm(bank.positions[pairs.current] - bank.positions[pairs.home], axis=1)
    assert np.all((d >= 0.15) & (d <= 1.5))
    width = KWARGS["panorama_shape"][1]
    p = np.repeat(np.arange(30), width)
    k = np.tile(np.arange(width), 30)
    labels = pair_labels(bank, pairs, p, k, oracle, helper)
    half_step = oracle.motion_spec.step_turn / 2
    for pair, column, label in zip(p, k, labels):
        x, y = bank.positions[pairs.current[pair]]
        tx, ty = pairs.target[pair]
        bearing = wrap_angle(math.atan2(ty - y, tx - x) - column * 2 * math.pi / width)
        if abs(abs(bearing) - half_step) > 1e-6:
            expected = FORWARD if abs(bearing) < half_step else (LEFT if bearing > 0 else RIGHT)
            assert label == expected, (pair, column, bearing)
    obs, labels = pair_samples(bank, pairs, 50, oracle, helper, rng)
    assert obs["panorama"].shape == obs["goal"].shape == (50, 16, 64, 3)
    assert set(labels.tolist()) <= {FORWARD, LEFT, RIGHT}


@pytest.mark.slow
def test_pretraining_runs_from_homing_train_and_records_its_fit(tmp_path):
    run = tmp_path / "run"
    main(["--timesteps", "128", "--out", str(run), "--n-envs", "1", "--vec", "dummy",
          "--no-progress", "--env-kwargs", json.dumps({**KWARGS, "max_episode_steps": 16}),
          "--hp", "n_steps=64", "--hp", "batch_size=32", "--hp", "n_epochs=1",
          "--hp", "eval_freq=128", "--hp", "eval_episodes=1", "--hp", "checkpoint_freq=128",
          "--hp", "features_dim=32", "--hp", "pretrain_samples=2048",
          "--hp", "pretrain_positions=40"])
    record = json.loads((run / "pretrain.json").read_text())
    assert record["positions"] == 40 and record["samples"][-1] == 2048
    for name in ("pretrain_model.zip", "model.zip", "learning_curve.png"):
        assert (run / name).is_file(), name


def test_pretraining_refuses_other_observation_keys():
    from stable_baselines3 import PPO

    from homing_train.learning.extractor import policy_kwargs_for
    from homing_train.learning.pretrain import pretrain

    env = gym.make("homing_gym/LocalHoming-v0", obs_keys=("panorama", "goal", "odometry"),
                   **KWARGS)
    model = PPO("MultiInputPolicy", env, n_steps=16, batch_size=16,
                policy_kwargs=policy_kwargs_for("panorama", features_dim=16))
    with pytest.raises(ValueError, match="obs_keys"):
        pretrain(model, "homing_gym/LocalHoming-v0",
                 {**KWARGS, "obs_keys": ("panorama", "goal", "odometry")}, 8, 1, 16, 0)
    env.close()


def test_init_policy_starts_a_run_from_saved_weights(tmp_path):
    import torch
    from stable_baselines3 import PPO

    from homing_train.learning.extractor import policy_kwargs_for
    from homing_train.learning.train import load_policy_weights

    env = gym.make("homing_gym/LocalHoming-v0", **KWARGS)
    make = lambda seed, dim: PPO("MultiInputPolicy", env, n_steps=16, batch_size=16,  # noqa: E731
                                 seed=seed, policy_kwargs=policy_kwargs_for("panorama",
                                                                            features_dim=dim))
    source, target = make(0, 16), make(1, 16)
    source.save(tmp_path / "source.zip")
    load_policy_weights(target, tmp_path / "source.zip")
    for key, value in source.policy.state_dict().items():
        assert torch.equal(value, target.policy.state_dict()[key]), key
    with pytest.raises(ValueError, match="does not fit"):
        load_policy_weights(make(2, 8), tmp_path / "source.zip")
    env.close()
    with pytest.raises(SystemExit):
        main(["--hp", f"init_policy={tmp_path / 'missing.zip'}", "--no-progress"])


def test_critic_warmup_leaves_the_actor_unchanged(tmp_path):
    """A run whose steps are all critic warm-up changes the value layers only."""
    import torch
    from stable_baselines3 import PPO

    run = tmp_path / "run"
    args = ["--timesteps", "64", "--n-envs", "1", "--vec", "dummy", "--no-progress",
            "--env-kwargs", json.dumps({**KWARGS, "max_episode_steps": 16}),
            "--hp", "n_steps=32", "--hp", "batch_size=16", "--hp", "n_epochs=2",
            "--hp", "eval_freq=1000", "--hp", "checkpoint_freq=1000", "--hp", "features_dim=16",
            "--hp", "learning_rate=0.01"]
    main([*args, "--out", str(tmp_path / "source")])
    main([*args, "--out", str(run), "--hp", f"init_policy={tmp_path / 'source' / 'model.zip'}",
          "--hp", "critic_warmup_steps=64"])
    before = PPO.load(tmp_path / "source" / "model.zip").policy.state_dict()
    after = PPO.load(run / "model.zip").policy.state_dict()
    critic = [k for k in before if k.startswith(("value_net", "mlp_extractor.value_net"))]
    assert critic and any(not torch.equal(before[k], after[k]) for k in critic)
    for key in set(before) - set(critic):
        assert torch.equal(before[key], after[key]), key


def test_a_bank_over_a_list_of_scenes_labels_near_pairs_stop():
    """Instance s of a bank over [random_rooms, random_nature] is scene s % 2 with its own
    world; with near positions (success_on="stop") entry 2k + 1 lies within ``near`` of
    2k, and exactly the near pairs closer than the stop radius are labelled stop."""
    from homing_baselines.motion import STOP
    from homing_train.learning.pretrain import STOP_SHARE, joined, near_pairs

    kwargs = {**KWARGS, "success_on": "stop"}
    envs = [gym.make("homing_gym/LocalHoming-v0", **{**kwargs, "scene": name})
            for name in ("random_rooms", "random_nature")]
    oracle = homing_baselines.make("oracle")
    prepare_policy(oracle, envs[0])
    helper = MotionHelper(oracle.motion_spec, oracle.motion)
    bank = render_bank(envs, 6, 4, seed=5, near=0.3, progress=False)
    for env in envs:
        env.close()
    assert [w.name for w in bank.scenes] == ["random_rooms", "random_nature"] * 2
    assert bank.scenes[0] is not bank.scenes[2]
    assert bank.scene_index.tolist() == np.repeat(np.arange(4), 6).tolist()
    gaps = np.linalg.norm(bank.positions[1::2] - bank.positions[::2], axis=1)
    assert np.all(gaps <= 0.3) and np.all(gaps > 0)
    with pytest.raises(ValueError, match="even number"):
        render_bank(envs[:1], 5, 1, seed=0, near=0.3, progress=False)
    rng = np.random.default_rng(1)
    pairs = joined(pair_set(bank, 20, (0.15, 1.5), oracle, rng, 0.22, progress=False),
                   near_pairs(bank, oracle))
    radius = STOP_SHARE * 0.15
    p = np.arange(len(pairs.current))
    labels = pair_labels(bank, pairs, p, np.zeros_like(p), oracle, helper, radius)
    d = np.linalg.norm(bank.positions[pairs.current] - bank.positions[pairs.home], axis=1)
    assert np.array_equal(labels == STOP, d < radius)
    assert 0 < np.sum(d < radius) < len(d)
