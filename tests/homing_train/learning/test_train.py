"""homing-train: smoke runs with both extractors, save/load round trip, --resume."""

import json
import re
from dataclasses import asdict
from pathlib import Path

import numpy as np
import pytest
import torch
import yaml

from homing_train.learning.extractor import (AlignedBandExtractor, CircularConv, CircularConv1d,
                                             HorizonBandExtractor, PanoramaGoalExtractor)
from homing_train.learning.train import (latest_checkpoint, load_hyperparams, main, make_config,
                                         parse_overrides, recipe)

# 36 rows: the smallest height SB3's NatureCNN (inside CombinedExtractor) accepts
TINY = ["--env-kwargs", json.dumps({"panorama_shape": [36, 64], "max_episode_steps": 16}),
        "--n-envs", "1", "--vec", "dummy", "--no-progress",
        "--hp", "n_steps=64", "--hp", "batch_size=32", "--hp", "n_epochs=1",
        "--hp", "eval_freq=128", "--hp", "eval_episodes=1", "--hp", "checkpoint_freq=128",
        "--hp", "features_dim=32"]


@pytest.mark.parametrize("extractor", ["panorama", "band", "align", "combined"])
def test_smoke_run_writes_a_complete_run_folder(tmp_path, extractor):
    run = tmp_path / extractor
    main(["--timesteps", "256", "--extractor", extractor, "--out", str(run), *TINY])
    for name in ("model.zip", "best_model.zip", "evaluations.npz", "config.yml", "command.txt",
                 "versions.json", "summary.json", "learning_curve.png"):
        assert (run / name).is_file(), name
    assert any((run / "tb").iterdir())
    evaluations = np.load(run / "evaluations.npz")
    assert list(evaluations["timesteps"]) == [128, 256]
    assert evaluations["successes"].shape == (2, 1)
    summary = json.loads((run / "summary.json").read_text())
    assert summary["timesteps"] == 256 and summary["env_steps_per_s"] > 0
    config = yaml.safe_load((run / "config.yml").read_text())
    assert config["extractor"] == extractor and config["ppo"]["n_steps"] == 64


def test_save_load_round_trip_gives_identical_actions(tmp_path):
    """The model in memory after training and the same model saved and loaded act alike."""
    import gymnasium as gym
    from stable_baselines3 import PPO

    from homing_train.learning.extractor import policy_kwargs_for

    env = gym.make("homing_gym/LocalHoming-v0", panorama_shape=(36, 64), max_episode_steps=16)
    model = PPO("MultiInputPolicy", env, n_steps=32, batch_size=16, n_epochs=1, seed=0,
                policy_kwargs=policy_kwargs_for("panorama", features_dim=32))
    model.learn(32)
    model.save(tmp_path / "model.zip")
    loaded = PPO.load(tmp_path / "model.zip")
    obs, _ = env.reset(seed=0)
    for _ in range(5):
        a, _ = model.predict(obs, deterministic=True)
        b, _ = loaded.predict(obs, deterministic=True)
        assert np.array_equal(a, b)
        obs, *_ = env.step(a)
    env.close()


def test_resume_continues_the_step_counter(tmp_path):
    from stable_baselines3 import PPO

    run = tmp_path / "run"
    main(["--timesteps", "128", "--out", str(run), *TINY])
    assert latest_checkpoint(run).name == "ppo_128_steps.zip"
    main(["--resume", str(run), "--timesteps", "256", "--no-progress"])
    assert PPO.load(run / "model.zip").num_timesteps == 256
    assert latest_checkpoint(run).name == "ppo_256_steps.zip"
    summary = json.loads((run / "summary.json").read_text())
    assert [(s["from_step"], s["to_step"]) for s in summary["sessions"]] == [(0, 128), (128, 256)]
    assert list(np.load(run / "evaluations.npz")["timesteps"]) == [128, 256]


def test_resume_without_a_checkpoint_refuses_rather_than_start_over(tmp_path, capsys):
    run = tmp_path / "run"
    main(["--timesteps", "64", "--out", str(run), *TINY, "--hp", "checkpoint_freq=1000"])
    assert latest_checkpoint(run) is None
    finished = (run / "model.zip").read_bytes()
    with pytest.raises(SystemExit) as err:
        main(["--resume", str(run), "--timesteps", "128", "--no-progress"])
    assert err.value.code == 2
    assert "no checkpoint in" in capsys.readouterr().err
    assert (run / "model.zip").read_bytes() == finished        # the finished model is kept


def test_training_never_draws_held_out_worlds_or_its_own_evaluation_worlds():
    import yaml

    from homing_train.learning.train import TrainConfig, check_seed_ranges, seed_ranges
    root = Path(__file__).parents[3]
    shipped = sorted([*root.glob("train/shipped/*.yml"),
                      *root.glob("train/learning/recipes/*.yml")])
    assert shipped
    for path in shipped:              # every run shipped now or before passes, from the start
        recorded = yaml.safe_load(path.read_text())["config"]
        config = TrainConfig(**{**recorded, "init_policy": None})   # a file of its machine
        check_seed_ranges(config, 0)
        check_seed_ranges(config, config.timesteps - config.n_envs)
    config = TrainConfig(**{**yaml.safe_load(shipped[0].read_text())["config"], "seed": 0,
                            "n_envs": 8, "init_policy": None})
    assert seed_ranges(config, 1000)["training"] == range(1000, 1008)
    with pytest.raises(ValueError, match="overlap the evaluation seeds 1000000"):
        check_seed_ranges(config, 999_996)     # a resume just before a million steps
    with pytest.raises(ValueError, match="held-out worlds .* from 10000000"):
        check_seed_ranges(TrainConfig(**{**vars(config), "seed": 9_500_000}), 0)


def test_hyperparameters_merge_and_reject_unknown_keys(tmp_path):
    settings = load_hyperparams("homing_gym/LocalHoming-v0")
    assert settings["env_kwargs"] == {"scene": "random_arena"} and settings["n_steps"] == 256
    assert parse_overrides(["n_steps=128", "env_kwargs={scene: arena}"]) == {
        "n_steps": 128, "env_kwargs": {"scene": "arena"}}
    with pytest.raises(ValueError, match="learning_rat"):
        make_config("homing_gym/LocalHoming-v0", {"learning_rat": 1e-3})
    with pytest.raises(ValueError, match="KEY=VALUE"):
        parse_overrides(["n_steps"])
    bad = tmp_path / "bad.yml"
    bad.write_text("default: [unclosed")
    with pytest.raises(ValueError, match="bad.yml"):
        load_hyperparams("homing_gym/LocalHoming-v0", bad)


def test_a_recipe_rebuilds_the_config_its_policy_was_trained_with(tmp_path, capsys):
    """A shipped policy's recipe and one of a policy no longer shipped (its zip left the
    package, its record moved to train/learning/recipes/)."""
    shipped = yaml.safe_load(Path("train/shipped/ppo_procedural_long.yml").read_text())
    env_id, settings = recipe("ppo_procedural_long")
    rebuilt = asdict(make_config(env_id, settings))
    assert rebuilt.pop("augment") is None      # recorded before augmentation existed: off
    assert rebuilt == shipped["config"]
    assert not Path("train/shipped/ppo_procedural_fast.zip").exists()
    recorded = yaml.safe_load(Path("train/learning/recipes/ppo_procedural_fast.yml").read_text())
    env_id, settings = recipe("ppo_procedural_fast")
    assert env_id == "homing_gym/LocalHoming-v0" and settings["n_steps"] == 64
    config = make_config(env_id, settings)
    assert {k: v for k, v in asdict(config).items() if k != "augment"} == recorded["config"]
    reseeded = make_config(env_id, {**settings, **parse_overrides(["n_epochs=3"])}, seed=1)
    assert (reseeded.seed, reseeded.ppo["n_epochs"], reseeded.n_envs) == (1, 3, 64)
    with pytest.raises(ValueError, match="unknown recipe 'ppo_fast'.*ppo_procedural_fast"):
        recipe("ppo_fast")
    (tmp_path / "old.yml").write_text("env_id: homing_gym/LocalHoming-v0\n")
    with pytest.raises(ValueError, match="old.yml records no training config"):
        recipe("old", [tmp_path])
    for bad in (["--recipe", "ppo_procedural_fast", "--env", "homing_gym/RouteFollowing-v0"],
                ["--recipe", "ppo_procedural_fast", "--resume", str(tmp_path)],
                ["--recipe", "ppo_procedural_fast", "--hyperparams", str(tmp_path / "old.yml")],
                ["--recipe", "nope"]):
        with pytest.raises(SystemExit):
            main(bad + ["--out", str(tmp_path / "run")])
    assert "RouteFollowing" in capsys.readouterr().err
    with pytest.raises(SystemExit):     # its warm start was a file of another machine
        main(["--recipe", "ppo_localhoming", "--out", str(tmp_path / "run")])
    assert "--hp init_policy=null" in capsys.readouterr().err
    assert not (tmp_path / "run").exists()


def test_circular_padding_makes_the_extractor_equivariant_to_azimuth_shifts():
    torch.manual_seed(0)
    conv = CircularConv(3, 4, kernel=3, stride=1)
    x = torch.rand(1, 3, 8, 32)
    shifted = torch.roll(x, 5, dims=3)
    assert torch.allclose(torch.roll(conv(x), 5, dims=3), conv(shifted), atol=1e-6)


def test_1d_circular_padding_is_equivariant_to_azimuth_shifts():
    torch.manual_seed(0)
    conv = CircularConv1d(6, 4, kernel=5, stride=1)
    x = torch.rand(2, 6, 32)
    assert torch.allclose(torch.roll(conv(x), 7, dims=2), conv(torch.roll(x, 7, dims=2)),
                          atol=1e-6)
    assert CircularConv1d(6, 4, kernel=5, stride=2)(x).shape == (2, 4, 16)


def test_band_extractor_takes_every_row_of_both_images_as_channels():
    import gymnasium as gym

    space = gym.spaces.Dict({
        "panorama": gym.spaces.Box(0, 255, (3, 8, 64), np.uint8),
        "goal": gym.spaces.Box(0, 255, (3, 8, 64), np.uint8),
        "odometry": gym.spaces.Box(-np.inf, np.inf, (3,), np.float32)})
    extractor = HorizonBandExtractor(space, features_dim=16)
    assert extractor.cnn[0].conv.in_channels == 2 * 3 * 8
    assert extractor.features_dim == 19
    obs = {"panorama": torch.rand(2, 3, 8, 64), "goal": torch.rand(2, 3, 8, 64),
           "odometry": torch.rand(2, 3)}
    out = extractor(obs)
    assert out.shape == (2, 19)
    assert torch.equal(out[:, 16:], obs["odometry"])
    changed = dict(obs, goal=obs["goal"].clone())
    changed["goal"][:, :, 5] += 0.5                 # one row of the goal image
    assert not torch.allclose(extractor(changed)[:, :16], out[:, :16])


def test_extractor_fuses_current_and_goal_early():
    import gymnasium as gym

    space = gym.spaces.Dict({
        "panorama": gym.spaces.Box(0, 255, (3, 16, 64), np.uint8),
        "goal": gym.spaces.Box(0, 255, (3, 16, 64), np.uint8),
        "odometry": gym.spaces.Box(-np.inf, np.inf, (3,), np.float32)})
    extractor = PanoramaGoalExtractor(space, features_dim=32)
    assert extractor.cnn[0].conv.in_channels == 6
    assert extractor.features_dim == 35
    out = extractor({"panorama": torch.rand(2, 3, 16, 64), "goal": torch.rand(2, 3, 16, 64),
                     "odometry": torch.rand(2, 3)})
    assert out.shape == (2, 35)
    with pytest.raises(ValueError, match="goal"):
        PanoramaGoalExtractor(gym.spaces.Dict({"panorama": space["panorama"]}))


def test_aligned_extractor_rotates_the_goal_into_the_current_frame():
    import gymnasium as gym

    torch.manual_seed(0)
    space = gym.spaces.Dict({
        "panorama": gym.spaces.Box(0, 255, (3, 8, 64), np.uint8),
        "goal": gym.spaces.Box(0, 255, (3, 8, 64), np.uint8),
        "odometry": gym.spaces.Box(-np.inf, np.inf, (3,), np.float32)})
    extractor = AlignedBandExtractor(space, features_dim=16, temperature=500.0)
    goal = torch.rand(3, 3, 8, 64)
    shifts = [0, 9, 50]
    current = torch.stack([torch.roll(g, k, dims=-1) for g, k in zip(goal, shifts)])
    f, g = extractor.column_features(current), extractor.column_features(goal)
    weights = extractor.shift_weights(f, g)
    # the robot turned by k columns: the weight sits on shift k, nowhere else
    assert weights.argmax(dim=1).tolist() == shifts
    assert torch.all(weights.max(dim=1).values > 0.99)
    # a view rotated by k columns leaves the same weights, rolled by k
    turned = extractor.shift_weights(torch.roll(f, 4, dims=-1), g)
    assert torch.allclose(turned, torch.roll(weights, 4, dims=-1), atol=1e-5)
    out = extractor({"panorama": current, "goal": goal, "odometry": torch.rand(3, 3)})
    assert out.shape == (3, 19)
    # layer-normalised features: zero mean, unit variance per sample
    assert torch.allclose(out[:, :16].mean(dim=1), torch.zeros(3), atol=1e-5)
    assert torch.allclose(out[:, :16].std(dim=1, unbiased=False), torch.ones(3), atol=0.02)
    # lighting offsets and gains drop out of the comparison
    brighter = extractor({"panorama": 0.5 * current + 0.2, "goal": goal,
                          "odometry": torch.zeros(3, 3)})
    assert torch.allclose(brighter[:, :16], out[:, :16], atol=1e-3)
    with pytest.raises(ValueError, match="strides must be 1"):
        AlignedBandExtractor(space, encoder=((8, 5, 2),))
    with pytest.raises(ValueError, match="goal"):
        AlignedBandExtractor(gym.spaces.Dict({"panorama": space["panorama"]}))


def test_aligned_extractor_compares_the_view_with_the_step_before():
    """With a ``previous`` key the head also sees what changed since the last step: a
    view equal to the one before (the robot stuck) gives other features than a changed
    one, the goal and the view being the same; without the key nothing changes."""
    import gymnasium as gym

    torch.manual_seed(3)
    box = gym.spaces.Box(0, 255, (3, 8, 64), np.uint8)
    space = gym.spaces.Dict({"panorama": box, "goal": box, "previous": box})
    extractor = AlignedBandExtractor(space, features_dim=16)
    assert extractor.previous_key == "previous" and extractor.features_dim == 16
    current, goal = torch.rand(2, 3, 8, 64), torch.rand(2, 3, 8, 64)
    still = extractor({"panorama": current, "goal": goal, "previous": current})
    moved = extractor({"panorama": current, "goal": goal,
                       "previous": torch.roll(current, 5, dims=-1)})
    assert still.shape == moved.shape == (2, 16)
    assert (still - moved).abs().max() > 1e-2
    # the same weights read as a two-key extractor would, apart from the fourth input
    plain = AlignedBandExtractor(gym.spaces.Dict({"panorama": box, "goal": box}),
                                 features_dim=16)
    assert plain.previous_key is None
    assert plain.head[0][0].conv.in_channels * 4 == extractor.head[0][0].conv.in_channels * 3
    with pytest.raises(ValueError, match="'previous' must have the images' shape"):
        AlignedBandExtractor(gym.spaces.Dict({"panorama": box, "goal": box, "previous":
                                              gym.spaces.Box(0, 255, (3, 4, 64), np.uint8)}))


def test_aligned_extractor_column_features_are_standardised_unit_columns():
    """The sums in ``column_features`` compute what its docstring defines (torch's own
    ``std`` and ``F.normalize``, which the shipped policies were trained with)."""
    import gymnasium as gym
    from torch.nn import functional as F

    torch.manual_seed(1)
    space = gym.spaces.Dict({k: gym.spaces.Box(0, 255, (3, 8, 64), np.uint8)
                             for k in ("panorama", "goal")})
    extractor = AlignedBandExtractor(space, features_dim=16)
    image = torch.rand(5, 3, 8, 64) * torch.rand(5, 1, 1, 1)     # a different contrast each
    flat = image.flatten(1, 2)
    standard = (flat - flat.mean(dim=(1, 2), keepdim=True)) / (
        flat.std(dim=(1, 2), keepdim=True) + 1e-3)
    expected = F.normalize(extractor.encoder(standard), dim=1)
    assert torch.allclose(extractor.column_features(image), expected, atol=1e-5)
    # one batch through the encoder for both images: the same as one image at a time
    obs = {"panorama": torch.rand(2, 3, 8, 64), "goal": torch.rand(2, 3, 8, 64)}
    both = extractor(obs)
    one = torch.cat([extractor({k: v[i:i + 1] for k, v in obs.items()}) for i in range(2)])
    assert torch.allclose(both, one, atol=1e-5)


def test_aligned_extractor_encodes_each_distinct_goal_once_with_the_same_result():
    import gymnasium as gym

    torch.manual_seed(2)
    space = gym.spaces.Dict({k: gym.spaces.Box(0, 255, (3, 8, 64), np.uint8)
                             for k in ("panorama", "goal")})
    extractor = AlignedBandExtractor(space, features_dim=16)
    goals = torch.rand(3, 3, 8, 64)
    which = torch.tensor([2, 0, 2, 2, 1, 0])
    batch = goals[which]
    distinct, inverse = extractor.distinct_images(batch)
    assert len(distinct) == 3 and torch.equal(distinct[inverse], batch)
    assert extractor.distinct_images(goals)[1] is None          # nothing repeats
    # one pixel apart is another goal
    close = batch.clone()
    close[3, 0, 0, 0] += 1 / 255
    assert len(extractor.distinct_images(close)[0]) == 4
    # a hash shared by two different images: every image encoded, nothing merged
    extractor.hash_weights.zero_()
    assert extractor.distinct_images(close)[1] is None
    extractor.hash_weights.copy_(torch.rand_like(extractor.hash_weights))
    # training (gradients on) gives the values and gradients of inference, image by image
    obs = {"panorama": torch.rand(6, 3, 8, 64), "goal": batch}
    out = extractor(obs)
    out.square().sum().backward()
    grads = [p.grad.clone() for p in extractor.parameters()]
    extractor.zero_grad()
    with torch.no_grad():
        plain = extractor(obs)
    assert torch.allclose(out, plain, atol=1e-5)
    whole = torch.cat([extractor({k: v[i:i + 1] for k, v in obs.items()}) for i in range(6)])
    whole.square().sum().backward()
    for got, want in zip(grads, (p.grad for p in extractor.parameters())):
        assert torch.allclose(got, want, rtol=1e-4, atol=1e-5)


def test_equal_goals_anywhere_in_a_large_minibatch_are_encoded_once():
    import gymnasium as gym

    space = gym.spaces.Dict({k: gym.spaces.Box(0, 255, (3, 16, 64), np.uint8)
                             for k in ("panorama", "goal")})
    extractor = AlignedBandExtractor(space, features_dim=16)
    goals = torch.rand(64, 3, 16, 64, generator=torch.Generator().manual_seed(3))
    which = torch.randperm(512, generator=torch.Generator().manual_seed(4)) % 64
    distinct, inverse = extractor.distinct_images(goals[which])
    assert len(distinct) == 64 and torch.equal(distinct[inverse], goals[which])


def test_extractor_kwargs_size_the_network_and_bad_ones_are_named():
    import gymnasium as gym

    from homing_train.learning.ppo_settings import extractor_arguments

    kwargs = extractor_arguments("align", {"encoder": [[8, 3, 1]], "head": [[16, 5, 2]],
                                           "temperature": 10})
    assert kwargs == {"encoder": ((8, 3, 1),), "head": ((16, 5, 2),), "temperature": 10.0}
    space = gym.spaces.Dict({k: gym.spaces.Box(0, 255, (3, 8, 64), np.uint8)
                             for k in ("panorama", "goal")})
    extractor = AlignedBandExtractor(space, features_dim=16, **kwargs)
    assert [m.conv.out_channels for m in extractor.encoder] == [8]
    assert extractor.head[0][0].conv.out_channels == 16
    for extractor_name, bad, named in [
            ("align", {"layers": [[8, 3, 1]]}, "unknown extractor_kwargs ['layers']"),
            ("align", {"encoder": [[8, 3, 2]]}, "extractor_kwargs.encoder"),
            ("align", {"head": [[8, 0, 1]]}, "extractor_kwargs.head"),
            ("align", {"head": []}, "extractor_kwargs.head"),
            ("align", {"temperature": "hot"}, "extractor_kwargs.temperature"),
            ("band", {"layers": [[8, 3]]}, "extractor_kwargs.layers"),
            ("combined", {"layers": [[8, 3, 1]]}, "unknown extractor_kwargs"),
            ("panorama", [[8, 3, 1]], "extractor_kwargs must be a mapping")]:
        with pytest.raises(ValueError, match=re.escape(named)):
            extractor_arguments(extractor_name, bad)
    with pytest.raises(ValueError, match="extractor_kwargs.encoder"):
        make_config("homing_gym/LocalHoming-v0", {"extractor": "align",
                                                  "extractor_kwargs": {"encoder": [[8, 3, 2]]}})


def test_suite_evaluates_and_compares_methods_on_one_suite(tmp_path, capsys):
    from homing_train.harness.suite import main as suite_main

    assert suite_main(["--arena", "--methods", "oracle", "--episodes", "2", "--workers", "1",
                       "--out", str(tmp_path)]) == 0
    table = (tmp_path / "table.md").read_text()
    assert "| oracle |" in table and "table.md" in capsys.readouterr().out
    for name in ("oracle.json", "oracle.csv", "success_vs_distance.png", "trajectories.png"):
        assert (tmp_path / name).is_file(), name
    with pytest.raises(SystemExit):
        suite_main(["--methods", "telepathy", "--out", str(tmp_path)])


def test_ship_copies_the_best_model_with_eval_settings_and_curve(tmp_path):
    from homing_train.harness.policies import ORACLE_DEMONSTRATIONS, shipped_policies
    from homing_train.learning.ship import ship_run

    run = tmp_path / "run"
    run.mkdir()
    (run / "best_model.zip").write_bytes(b"best")
    (run / "model.zip").write_bytes(b"final")
    (run / "learning_curve.png").write_bytes(b"png")
    (run / "command.txt").write_text("homing-train --seed 3\n")
    (run / "summary.json").write_text(json.dumps(
        {"timesteps": 1000, "wall_time_s": 10.0, "env_steps_per_s": 100.0}))
    (run / "config.yml").write_text(yaml.safe_dump({
        "env_id": "homing_gym/LocalHoming-v0",
        "env_kwargs": {"scene": "random_arena", "action_type": "discrete"}}))
    shipped = tmp_path / "shipped"
    target = ship_run(run, "p", shipped)
    assert target.read_bytes() == b"best"
    meta = yaml.safe_load((shipped / "p.yml").read_text())
    assert meta["eval_env_kwargs"] == {"action_type": "discrete"}
    assert meta["eval_params"] == {"deterministic": True}
    assert meta["timesteps"] == 1000 and meta["commands"] == ["homing-train --seed 3"]
    assert meta["privileged"] == ""
    assert (shipped / "p_curve.png").read_bytes() == b"png"
    assert ship_run(run, "q", shipped, model="final", stochastic=True).read_bytes() == b"final"
    meta = yaml.safe_load((shipped / "q.yml").read_text())
    assert meta["eval_params"] == {"deterministic": False} and meta["model"] == "model.zip"
    with pytest.raises(ValueError, match="pretrain_model.zip is missing"):
        ship_run(run, "s", shipped, model="pretrain")
    with pytest.raises(ValueError, match="unknown model"):
        ship_run(run, "t", shipped, model="latest")
    ship_run(run, "u", shipped, privileged="odometry")
    assert yaml.safe_load((shipped / "u.yml").read_text())["privileged"] == "odometry"
    (run / "config.yml").write_text(yaml.safe_dump({
        "env_id": "homing_gym/LocalHoming-v0", "env_kwargs": {}, "pretrain_samples": 8}))
    ship_run(run, "v", shipped)
    assert yaml.safe_load((shipped / "v.yml").read_text())["privileged"] == ORACLE_DEMONSTRATIONS
    assert shipped_policies(shipped)["v"].privileged == ORACLE_DEMONSTRATIONS
    (run / "summary.json").unlink()
    with pytest.raises(ValueError, match="summary.json"):
        ship_run(run, "r", shipped)


def test_stochastic_evaluation_of_a_model_is_reproducible_per_episode(tmp_path):
    import gymnasium as gym
    from stable_baselines3 import PPO

    from homing_train.harness.evaluate import evaluate
    from homing_train.learning.extractor import policy_kwargs_for

    kwargs = {"panorama_shape": [16, 64], "max_episode_steps": 12, "action_type": "discrete"}
    env = gym.make("homing_gym/LocalHoming-v0", **kwargs)
    PPO("MultiInputPolicy", env, n_steps=16, batch_size=16, n_epochs=1, seed=0,
        policy_kwargs=policy_kwargs_for("panorama", features_dim=16)).save(tmp_path / "m.zip")
    env.close()

    def paths(**params):
        result = evaluate(str(tmp_path / "m.zip"), episodes=2, seed=5, env_kwargs=kwargs,
                          params=params, progress=False)
        assert result.params["deterministic"] == params.get("deterministic", True)
        return [np.asarray(r.trajectory) for r in result.episodes]

    first, again = paths(deterministic=False), paths(deterministic=False)
    assert all(np.array_equal(a, b) for a, b in zip(first, again))
    modes = paths()
    assert not all(np.array_equal(a, b) for a, b in zip(first, modes))
    with pytest.raises(ValueError, match="deterministic"):
        evaluate(str(tmp_path / "m.zip"), episodes=1, env_kwargs=kwargs,
                 params={"deterministic": "maybe"})


@pytest.mark.slow
def test_imitation_fits_the_policy_to_the_oracle_labels(tmp_path):
    """DAgger's refit raises the policy's agreement with the oracle on the states it
    collected, and a run with imitation records it and then trains PPO as usual."""
    import gymnasium as gym
    from stable_baselines3 import PPO

    from homing_train.learning.extractor import policy_kwargs_for
    from homing_train.learning.imitation import collect, dagger, fit

    kwargs = {"panorama_shape": [16, 64], "max_episode_steps": 40, "action_type": "discrete",
              "control_period": 0.2}
    env = gym.make("homing_gym/LocalHoming-v0", **kwargs)
    model = PPO("MultiInputPolicy", env, n_steps=16, batch_size=16, n_epochs=1, seed=0,
                learning_rate=1e-3, policy_kwargs=policy_kwargs_for("panorama", features_dim=16))
    import homing_baselines
    from homing_train.harness.rollout import prepare_policy

    oracle = homing_baselines.make("oracle")
    prepare_policy(oracle, env)
    rng = np.random.default_rng(0)
    obs, labels, before = collect(env, oracle, model, 1.0, 6, 100, rng)
    data = {k: np.asarray(v) for k, v in obs.items()}
    labels = np.asarray(labels)
    first = fit(model, data, labels, 1, 32, rng)
    last = fit(model, data, labels, 30, 32, rng)
    assert last < first
    mine, _ = model.predict(data, deterministic=True)
    assert np.mean(mine == labels) > max(before, np.mean(labels == np.bincount(labels).argmax()))
    result = dagger(model, "homing_gym/LocalHoming-v0", kwargs, 2, 1, 1, seed=7,
                    progress=False)
    assert result.beta == [1.0, 0.5] and result.samples[1] > result.samples[0]
    env.close()

    run = tmp_path / "run"
    main(["--timesteps", "64", "--out", str(run), *TINY, "--hp", "imitation_iterations=1",
          "--hp", "imitation_episodes=1", "--hp", "imitation_epochs=1"])
    assert json.loads((run / "imitation.json").read_text())["beta"] == [1.0]
    assert (run / "imitation_model.zip").is_file() and (run / "model.zip").is_file()


def test_suite_runs_the_controllers_made_for_the_env():
    from homing_train.harness.suite import suite_methods

    local = suite_methods("homing_gym/LocalHoming-v0")
    assert {"oracle", "random", "snapshot", "warping", "distance"} <= set(local)
    assert not {"multires", "selfsimilar", "bearing", "bearing-longrange"} & set(local)
    assert "multires" in suite_methods("homing_gym/WorkLocations-v0")
    assert "bearing-longrange" in suite_methods("homing_gym/LongRangeHoming-v0")


def test_sigterm_saves_the_run_as_ctrl_c_does(tmp_path, monkeypatch):
    import os
    import signal

    from stable_baselines3 import PPO

    real_learn = PPO.learn

    def learn_then_terminate(self, *args, **kwargs):
        real_learn(self, *args, **kwargs)
        os.kill(os.getpid(), signal.SIGTERM)      # `kill PID` of a background run

    before = signal.getsignal(signal.SIGTERM)
    run = tmp_path / "run"
    monkeypatch.setattr(PPO, "learn", learn_then_terminate)
    assert main(["--timesteps", "128", "--out", str(run), *TINY]) == 130
    summary = json.loads((run / "summary.json").read_text())
    assert summary["interrupted"] and (run / "model.zip").is_file()
    assert latest_checkpoint(run).name == "ppo_128_steps.zip"
    assert signal.getsignal(signal.SIGTERM) is before


def test_ctrl_c_saves_the_run_and_resume_continues_with_new_episode_seeds(tmp_path,
                                                                          monkeypatch):
    from stable_baselines3 import PPO

    from homing_train.learning import train as train_module

    real_learn = PPO.learn

    def learn_then_interrupt(self, *args, **kwargs):
        real_learn(self, *args, **kwargs)
        raise KeyboardInterrupt

    run = tmp_path / "run"
    monkeypatch.setattr(PPO, "learn", learn_then_interrupt)
    assert main(["--timesteps", "128", "--out", str(run), *TINY]) == 130
    summary = json.loads((run / "summary.json").read_text())
    assert summary["interrupted"] and (run / "model.zip").is_file()
    assert latest_checkpoint(run).name == "ppo_128_steps.zip"
    monkeypatch.setattr(PPO, "learn", real_learn)
    seeds = []
    real_make_vec = train_module.make_vec
    monkeypatch.setattr(train_module, "make_vec",
                        lambda config, n, seed, *rest, **kw: seeds.append(seed)
                        or real_make_vec(config, n, seed, *rest, **kw))
    assert main(["--resume", str(run), "--timesteps", "256", "--no-progress"]) == 0
    config_seed = yaml.safe_load((run / "config.yml").read_text())["seed"]
    assert seeds[0] == config_seed + 128          # training envs: not the first run's seeds
    summary = json.loads((run / "summary.json").read_text())
    assert not summary["interrupted"] and summary["timesteps"] == 256
    assert summary["wall_time_s"] == pytest.approx(
        sum(s["wall_time_s"] for s in summary["sessions"]))


def test_a_bad_env_setting_is_one_error_and_leaves_no_run_folder(tmp_path, capsys):
    run = tmp_path / "bad"
    with pytest.raises(SystemExit) as exit_:
        main(["--timesteps", "64", "--out", str(run), "--n-envs", "2", "--vec", "subproc",
              "--env-kwargs", '{"scene": "nowhere"}', "--no-progress"])
    assert exit_.value.code == 2
    err = capsys.readouterr().err
    assert err.count("unknown scene 'nowhere'") == 1 and not run.exists()


@pytest.mark.slow
@pytest.mark.parametrize("grouping", [[], ["--hp", "workers=1"]], ids=["per-env", "grouped"])
def test_an_env_error_in_a_subprocess_worker_is_said_once_not_as_eoferror(tmp_path, grouping):
    import os
    import subprocess
    import sys

    # a user env that fails at its 5th step, registered through --import in every worker
    (tmp_path / "failing_env.py").write_text(
        "import gymnasium as gym\n"
        "class FailAtStep5(gym.Wrapper):\n"
        "    steps = 0\n"
        "    def step(self, action):\n"
        "        self.steps += 1\n"
        "        if self.steps == 5:\n"
        "            raise ValueError('boom: the user env failed at step 5')\n"
        "        return self.env.step(action)\n"
        "def make(**kwargs):\n"
        "    return FailAtStep5(gym.make('homing_gym/LocalHoming-v0', **kwargs).unwrapped)\n"
        "gym.register('failing/LocalHoming-v0', entry_point=make, max_episode_steps=16)\n")
    env = {**os.environ, "PYTHONPATH": str(tmp_path)}
    run = tmp_path / "run"
    tiny = [a if a != "dummy" else "subproc" for a in TINY]
    tiny[tiny.index("--n-envs") + 1] = "2"
    done = subprocess.run([sys.executable, "-m", "homing_train.learning.train", "--import",
                           "failing_env", "--env", "failing/LocalHoming-v0", "--timesteps", "64",
                           "--out", str(run), *tiny, *grouping], capture_output=True,
                          text=True, env=env,
                          timeout=300)
    assert done.returncode == 2, done.stderr[-2000:]
    assert done.stderr.count("boom: the user env failed at step 5") == 1, done.stderr[-3000:]
    assert "ValueError" in done.stderr and "EOFError" not in done.stderr
    assert "Traceback" not in done.stderr


def test_benchmark_measures_the_ppo_time_split_and_writes_nothing(tmp_path, capsys,
                                                                  monkeypatch):
    monkeypatch.chdir(tmp_path)
    args = ["--benchmark", "128", "--n-envs", "1", "--vec", "dummy", "--hp", "n_steps=64",
            "--hp", "batch_size=32", "--hp", "n_epochs=1",
            "--env-kwargs", '{"scene": "arena", "panorama_shape": [16, 64]}']
    assert main(args) == 0
    rows = [line for line in capsys.readouterr().out.splitlines() if line.startswith("| Local")]
    assert len(rows) == 1
    cells = [c.strip() for c in rows[0].strip("|").split("|")]
    env_rate, inference, ppo, rollout, update = map(float, cells[2:7])
    assert min(env_rate, inference, ppo) > 0 and min(rollout, update) >= 0
    assert list(tmp_path.iterdir()) == []
    with pytest.raises(SystemExit):
        main(["--benchmark", "10", "--hp", "n_steps=64"])     # less than one rollout
    # from a trained network of the same layout: its episodes, named in the row
    from homing_train.learning.train import make_vec, new_model

    config = make_config("homing_gym/LocalHoming-v0", {
        "n_envs": 1, "vec": "dummy", "n_steps": 64, "batch_size": 32, "n_epochs": 1,
        "env_kwargs": {"scene": "arena", "panorama_shape": [16, 64]}})
    env = make_vec(config, 1, 0)
    new_model(config, env).save(tmp_path.parent / "trained.zip")
    env.close()
    assert main(args + ["--hp", f"init_policy={tmp_path.parent / 'trained.zip'}"]) == 0
    rows = [line for line in capsys.readouterr().out.splitlines() if line.startswith("| Local")]
    assert len(rows) == 1 and "from trained.zip" in rows[0]
    with pytest.raises(SystemExit):           # another layout: refused with its reason
        main(args + ["--hp", "features_dim=8",
                     "--hp", f"init_policy={tmp_path.parent / 'trained.zip'}"])
    assert "does not fit" in capsys.readouterr().err


def test_a_list_of_scenes_gives_each_env_its_own_and_bad_lists_are_refused():
    from homing_train.learning.train import TrainConfig, make_vec

    config = TrainConfig("homing_gym/LocalHoming-v0", n_envs=3, vec="dummy",
                         env_kwargs={"scene": ["random_rooms", "random_nature"],
                                     "panorama_shape": [8, 32]})
    env = make_vec(config, 3, seed=0)
    env.reset()
    names = [e.unwrapped.scene.name for e in env.venv.envs]
    env.close()
    assert names == ["random_rooms", "random_nature", "random_rooms"]
    assert config.env_kwargs_of(2)["scene"] == "random_rooms" and config.n_scenes == 2
    for bad in ([], ["random_rooms", 3]):
        with pytest.raises(ValueError, match="list of scene names"):
            TrainConfig("homing_gym/LocalHoming-v0", env_kwargs={"scene": bad})
    both = {"scene": ["random_rooms", "random_nature"]}
    with pytest.raises(ValueError, match="DAgger takes one scene"):
        TrainConfig("homing_gym/LocalHoming-v0", imitation_iterations=1, env_kwargs=both)
    with pytest.raises(ValueError, match="needs pretrain_scenes >= 2"):
        TrainConfig("homing_gym/LocalHoming-v0", pretrain_samples=10, env_kwargs=both)
    TrainConfig("homing_gym/LocalHoming-v0", pretrain_samples=10, pretrain_scenes=2,
                env_kwargs=both)


def test_phase_threads_run_rollouts_on_one_thread_and_updates_on_the_settings():
    from homing_train.learning.thread_split import phase_threads

    before = torch.get_num_threads()
    try:
        callback = phase_threads(2)
        callback.on_rollout_start()
        assert torch.get_num_threads() == 1
        callback.on_rollout_end()
        assert torch.get_num_threads() == 2
    finally:
        torch.set_num_threads(before)
