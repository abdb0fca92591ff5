"""homing-train's PPO settings: every value checked before a run starts, schedules and
policy keywords reach the PPO model."""

import pytest
import torch

from homing_train.learning.ppo_settings import check_ppo, ppo_arguments
from homing_train.learning.train import make_config, make_vec, new_model

LOCAL = "homing_gym/LocalHoming-v0"


@pytest.mark.parametrize("ppo, message", [
    ({"n_step": 64}, r"unknown PPO hyperparameters \['n_step'\]"),
    ({"n_steps": 0}, "n_steps must be an integer >= 2 .*got 0"),
    ({"n_epochs": 2.5}, "n_epochs must be an integer >= 1"),
    ({"gamma": 1.5}, r"gamma must be a number in \(0, 1\], got 1.5"),
    ({"gae_lambda": float("nan")}, "gae_lambda must be"),
    ({"learning_rate": "lin_fast"}, "learning_rate must be a positive number or 'lin_X'"),
    ({"learning_rate": -1e-3}, "learning_rate must be"),
    ({"clip_range": 0}, "clip_range must be"),
    ({"normalize_advantage": "yes"}, "normalize_advantage must be true or false"),
    ({"target_kl": -0.1}, "target_kl must be null"),
    ({"policy_kwargs": {"activation_fn": "sigmoid"}}, r"policy_kwargs.activation_fn must be "
                                                      r"one of \['tanh'"),
    ({"policy_kwargs": {"net_arch": [64, "wide"]}}, "policy_kwargs.net_arch must be a list"),
    ({"policy_kwargs": {"features_extractor_class": "x"}}, "unknown policy_kwargs"),
    ({"policy_kwargs": [64]}, "policy_kwargs must be a mapping"),
    ({"n_steps": 64, "batch_size": 256}, r"batch_size \(256\) must be at most one rollout, "
                                         r"n_steps x n_envs = 128"),
])
def test_bad_settings_are_named_with_what_is_allowed(ppo, message):
    with pytest.raises(ValueError, match=message):
        check_ppo(ppo, n_envs=2)
    with pytest.raises(ValueError, match=next(iter(ppo))):    # a run's config names it too
        make_config(LOCAL, {"n_envs": 2, **ppo})


def test_every_problem_is_reported_at_once():
    with pytest.raises(ValueError) as err:
        check_ppo({"gamma": 2.0, "ent_coef": -1.0, "policy_kwargs": {"ortho_init": 1}}, 1)
    assert all(key in str(err.value) for key in ("gamma", "ent_coef", "ortho_init"))


def test_linear_schedules_and_activation_names_become_ppo_arguments():
    args = ppo_arguments({"learning_rate": "lin_3e-4", "clip_range": 0.1,
                          "policy_kwargs": {"activation_fn": "relu", "net_arch": [16]}})
    lr = args["learning_rate"]
    assert lr(1.0) == pytest.approx(3e-4) and lr(0.5) == pytest.approx(1.5e-4)
    assert lr(0.0) == 0.0 and args["clip_range"] == 0.1
    assert args["policy_kwargs"] == {"activation_fn": torch.nn.ReLU, "net_arch": [16]}


def test_the_model_is_built_with_the_settings(tmp_path):
    config = make_config(LOCAL, {
        "n_envs": 1, "vec": "dummy", "features_dim": 16, "n_steps": 32, "batch_size": 16,
        "env_kwargs": {"panorama_shape": [16, 64]}, "learning_rate": "lin_1e-3",
        "policy_kwargs": {"net_arch": {"pi": [8], "vf": [12]}, "activation_fn": "elu"}})
    env = make_vec(config, 1, 0)
    try:
        model = new_model(config, env)
        policy_net = model.policy.mlp_extractor.policy_net
        value_net = model.policy.mlp_extractor.value_net
        assert [m.out_features for m in policy_net if isinstance(m, torch.nn.Linear)] == [8]
        assert [m.out_features for m in value_net if isinstance(m, torch.nn.Linear)] == [12]
        assert any(isinstance(m, torch.nn.ELU) for m in policy_net)
        assert model.lr_schedule(0.5) == pytest.approx(5e-4)
        assert model.policy.features_extractor.features_dim == 16   # the run's extractor kept
    finally:
        env.close()


def test_state_dependent_exploration_needs_continuous_actions():
    config = make_config(LOCAL, {"n_envs": 1, "vec": "dummy", "use_sde": True,
                                 "env_kwargs": {"panorama_shape": [16, 64],
                                                "action_type": "discrete"}})
    env = make_vec(config, 1, 0)
    try:
        with pytest.raises(ValueError, match="use_sde needs continuous actions"):
            new_model(config, env)
    finally:
        env.close()


def test_the_device_must_exist_here(capsys, tmp_path, monkeypatch):
    """SB3 would quietly train on the CPU when 'cuda' is missing: refused up front."""
    from homing_train.learning.ppo_settings import check_device
    from homing_train.learning.train import main

    check_device("cpu")
    check_device("auto")
    with pytest.raises(ValueError, match="'cdua' is not a torch device"):
        make_config(LOCAL, {"device": "cdua"})
    monkeypatch.setattr(torch.cuda, "is_available", lambda: False)
    with pytest.raises(ValueError, match="'cuda:1': torch .* sees no such device"):
        check_device("cuda:1")
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit):
        main(["--device", "cuda", "--timesteps", "64"])
    assert "sees no such device" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []                  # no run folder left behind
