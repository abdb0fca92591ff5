"""Does a policy look at its observations? Saturation of its tanh layers and the spread
of its outputs across observations.

SB3's actor-critic MLPs use tanh. A features extractor whose outputs grow unbounded
(ReLU features that the critic scales up to fit large returns) drives those tanh units
to +-1, where their gradient vanishes: the actor then outputs one action distribution
and the critic one value for every observation, and PPO can only learn the marginal
action frequencies. :func:`saturation_report` measures this on real observations:

```bash
python -m homing_train.learning.saturation RUN/model.zip --env-kwargs '{"scene": "random_rooms"}'
```

It loads the zip without unpickling (:mod:`homing_train.learning.policy_zip`).
"""

from __future__ import annotations

import sys
from dataclasses import dataclass

import gymnasium as gym
import numpy as np

from homing_gym.cli import command_parser, parse_json_kwargs, seed_value

#: ``|tanh(x)|`` above this counts as saturated (the gradient ``1 - tanh^2`` below 0.02).
SATURATED = 0.99


@dataclass
class LayerSaturation:
    """One tanh layer: the share of its unit activations (over units and observations)
    with ``|value| > SATURATED``, and the mean over units of their standard deviation
    across observations."""

    name: str
    saturated_share: float
    spread: float


@dataclass
class SaturationReport:
    """Every tanh layer of the actor and critic MLPs, and the standard deviation across
    observations of the features, action probabilities (discrete actions) or means
    (continuous), and values, each averaged over its entries."""

    layers: list[LayerSaturation]
    features_spread: float
    action_spread: float
    value_spread: float
    observations: int

    def markdown(self) -> str:
        """The report as a Markdown table."""
        rows = ["| layer | saturated share | spread across observations |", "|---|---:|---:|"]
        rows += [f"| {layer.name} | {layer.saturated_share:.3f} | {layer.spread:.3g} |"
                 for layer in self.layers]
        rows += [f"| features | | {self.features_spread:.3g} |",
                 f"| action | | {self.action_spread:.3g} |",
                 f"| value | | {self.value_spread:.3g} |"]
        return f"{self.observations} observations\n\n" + "\n".join(rows)


def saturation_report(policy, observations: dict[str, np.ndarray]) -> SaturationReport:
    """Measure ``policy`` (an SB3 ``ActorCriticPolicy``) on a batch of observations
    (a dict of arrays with a leading batch axis, as the env returns them)."""
    import torch
    from stable_baselines3.common.preprocessing import preprocess_obs
    from torch import nn

    captured: dict[str, torch.Tensor] = {}
    hooks = [module.register_forward_hook(
        lambda _m, _i, out, name=name: captured.__setitem__(name, out.detach()))
        for name, module in policy.named_modules() if isinstance(module, nn.Tanh)]
    try:
        with torch.no_grad():
            tensors, _ = policy.obs_to_tensor(observations)
            distribution = policy.get_distribution(tensors).distribution
            values = policy.predict_values(tensors)
            features = policy.pi_features_extractor(preprocess_obs(
                tensors, policy.observation_space, normalize_images=policy.normalize_images))
    finally:
        for hook in hooks:
            hook.remove()
    actions = getattr(distribution, "probs", None)
    actions = distribution.mean if actions is None else actions
    layers = [LayerSaturation(name, float((out.abs() > SATURATED).float().mean()),
                              float(out.std(dim=0).mean()))
              for name, out in captured.items()]
    n = len(values)
    return SaturationReport(layers, float(features.std(dim=0).mean()),
                            float(actions.std(dim=0).mean()), float(values.std(dim=0).mean()), n)


def reset_observations(env_id: str, env_kwargs: dict, count: int, seed: int) -> dict[str, np.ndarray]:
    """The first observations of ``count`` episodes (seeds ``seed``, ``seed + 1``, ...),
    stacked along a new first axis."""
    with gym.make(env_id, **env_kwargs) as env:
        first = [env.reset(seed=seed + i)[0] for i in range(count)]
    return {key: np.stack([obs[key] for obs in first]) for key in first[0]}


def main(argv: list[str] | None = None) -> int:
    parser = command_parser("python -m homing_train.learning.saturation", __doc__)
    parser.add_argument("policy", help="an SB3 PPO zip")
    parser.add_argument("--env", default="homing_gym/LocalHoming-v0")
    parser.add_argument("--env-kwargs", default=None, metavar="JSON",
                        help="gym.make kwargs matching the policy's observation space")
    parser.add_argument("--observations", type=int, default=30,
                        help="episodes whose first observation is used (default 30)")
    parser.add_argument("--seed", type=seed_value, default=0)
    parser.add_argument("--trust-policy", action="store_true",
                        help="unpickle the zip (runs code from the file)")
    args = parser.parse_args(argv)
    if args.observations < 2:
        parser.error(f"--observations must be at least 2 (a spread needs two); got "
                     f"{args.observations}")
    from homing_train.learning.policy_zip import load_policy

    loaded = load_policy(args.policy, trust=args.trust_policy)
    observations = reset_observations(args.env, parse_json_kwargs(args.env_kwargs),
                                      args.observations, args.seed)
    print(saturation_report(loaded.policy, observations).markdown())
    return 0


if __name__ == "__main__":
    sys.exit(main())
