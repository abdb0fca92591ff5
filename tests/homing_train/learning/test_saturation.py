"""The saturation report: a policy whose tanh layers are driven to +-1 is flagged, and its
outputs no longer vary with the observation."""

import numpy as np
import torch
from gymnasium import spaces
from stable_baselines3.common.policies import MultiInputActorCriticPolicy

from homing_train.learning.saturation import saturation_report


def _policy() -> MultiInputActorCriticPolicy:
    torch.manual_seed(0)
    space = spaces.Dict({"x": spaces.Box(-1, 1, (8,), np.float32)})
    return MultiInputActorCriticPolicy(space, spaces.Discrete(4), lambda _: 0.0)


def _observations() -> dict[str, np.ndarray]:
    return {"x": np.random.default_rng(0).uniform(-1, 1, (50, 8)).astype(np.float32)}


def test_a_fresh_policy_is_not_saturated_and_responds_to_its_input():
    report = saturation_report(_policy(), _observations())
    assert [layer.name for layer in report.layers] == [
        "mlp_extractor.policy_net.1", "mlp_extractor.policy_net.3",
        "mlp_extractor.value_net.1", "mlp_extractor.value_net.3"]
    assert all(layer.saturated_share < 0.05 for layer in report.layers)
    assert report.features_spread > 0.3        # the features are the inputs, uniform(-1, 1)
    assert report.value_spread > 1e-3 and report.action_spread > 1e-4
    assert report.observations == 50
    assert "mlp_extractor.value_net.1" in report.markdown()


def test_huge_first_layer_weights_saturate_it_and_flatten_the_outputs():
    policy = _policy()
    fresh = saturation_report(policy, _observations())
    with torch.no_grad():
        for net in (policy.mlp_extractor.policy_net, policy.mlp_extractor.value_net):
            net[0].weight.mul_(1000.0)
            net[0].bias.fill_(5000.0)         # every unit pushed to +1
    report = saturation_report(policy, _observations())
    first = {layer.name: layer for layer in report.layers}
    assert first["mlp_extractor.policy_net.1"].saturated_share == 1.0
    assert first["mlp_extractor.value_net.1"].saturated_share == 1.0
    assert first["mlp_extractor.policy_net.1"].spread < 1e-6
    assert report.action_spread < 1e-6 < fresh.action_spread
    assert report.value_spread < 1e-6 < fresh.value_spread


def test_command_reports_a_saved_policy_on_env_observations(tmp_path, capsys):
    import json

    import gymnasium as gym
    import pytest
    from stable_baselines3 import PPO

    import homing_gym  # noqa: F401  (registers the envs)
    from homing_train.learning.extractor import policy_kwargs_for
    from homing_train.learning.saturation import main

    kwargs = {"panorama_shape": [8, 32], "action_type": "discrete"}
    with gym.make("homing_gym/LocalHoming-v0", **kwargs) as env:
        model = PPO("MultiInputPolicy", env, n_steps=64, device="cpu", seed=0,
                    policy_kwargs=policy_kwargs_for("align", features_dim=16))
        model.save(tmp_path / "m.zip")
    assert main([str(tmp_path / "m.zip"), "--env-kwargs", json.dumps(kwargs),
                 "--observations", "3"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("3 observations")
    assert "| mlp_extractor.policy_net.1 |" in out and "| value |" in out
    with pytest.raises(SystemExit):
        main([str(tmp_path / "m.zip"), "--observations", "1"])
