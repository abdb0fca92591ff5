"""Warm-starting a PPO policy by imitation of the ``oracle`` (DAgger), before PPO proper.

PPO from pixels alone needs millions of steps to find home often enough to learn from;
on 2 CPU cores a run gets a few hundred thousand. ``homing-train --hp
imitation_iterations=N`` therefore first fits the PPO policy's action distribution to the
``oracle`` controller's actions (it drives the true shortest path; see
:mod:`homing_baselines.oracle`) with DAgger (Ross, Gordon & Bagnell 2011): iteration ``i`` runs
``imitation_episodes`` episodes in which each step executes the oracle's action with
probability ``beta = 0.5 ** i`` and the policy's own sampled action otherwise, labels
*every* visited state with the oracle's action, adds the pairs to the data set and refits
(maximum likelihood of the labels under the policy, ``imitation_epochs`` passes). Then
PPO trains the same network on the env's reward as usual.

The oracle's ground truth is only the *teacher's* input at training time: the policy
itself acts from the observation (panorama and goal image) alone, in training and in
evaluation. The label of a state is the first action of a fresh oracle decision from that
state (its move queue cleared every step), so it is a function of the state, not of the
moves the oracle had planned before the policy took over.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import gymnasium as gym
import numpy as np
from tqdm.auto import tqdm

import homing_baselines
from homing_train.harness.rollout import prepare_policy, rollout


@dataclass
class ImitationResult:
    """What DAgger did: per iteration, beta, samples so far, the final fit loss (mean
    negative log-likelihood of the oracle's actions) and the share of visited states in
    which the policy's most likely action was the oracle's (measured before refitting)."""

    beta: list[float] = field(default_factory=list)
    samples: list[int] = field(default_factory=list)
    loss: list[float] = field(default_factory=list)
    agreement: list[float] = field(default_factory=list)


def oracle_label(oracle, observation) -> int | np.ndarray:
    """The oracle's action for the current state, from a fresh decision."""
    oracle.reset()
    action, _ = oracle.predict(observation)
    return action


class DaggerMixture:
    """The DAgger behaviour policy (Ross et al. 2011): in each state it acts with the
    oracle's label with probability ``beta``, else with an action sampled from ``model``;
    it records every visited observation, its oracle label and whether the model's most
    likely action agreed."""

    def __init__(self, oracle, model, beta: float, rng: np.random.Generator,
                 keys: list[str]):
        self.oracle, self.model, self.beta, self.rng = oracle, model, beta, rng
        self.observations: dict[str, list] = {k: [] for k in keys}
        self.labels: list = []
        self.agree: list[bool] = []

    def predict(self, obs, state=None, episode_start=None):
        label = oracle_label(self.oracle, obs)
        mine, _ = self.model.predict(obs, deterministic=True)
        self.agree.append(bool(np.array_equal(np.asarray(mine), np.asarray(label))))
        for key, value in obs.items():
            self.observations[key].append(value)
        self.labels.append(label)
        if self.rng.random() < self.beta:
            return label, state
        action, _ = self.model.predict(obs, deterministic=False)
        return action, state


def collect(env: gym.Env, oracle, model, beta: float, episodes: int, seed: int,
            rng: np.random.Generator) -> tuple[dict[str, list], list, float]:
    """Run ``episodes`` (seeds ``seed..``) mixing oracle and policy actions; returns the
    visited observations, their oracle labels and the policy's agreement with them."""
    mixture = DaggerMixture(oracle, model, beta, rng, list(env.observation_space.spaces))
    for i in range(episodes):
        rollout(env, mixture, seed + i)
    agreement = float(np.mean(mixture.agree)) if mixture.agree else 0.0
    return mixture.observations, mixture.labels, agreement


def fit(model, observations: dict[str, np.ndarray], labels: np.ndarray, epochs: int,
        batch_size: int, rng: np.random.Generator) -> float:
    """Maximum-likelihood fit of ``model``'s policy to ``labels``; returns the mean loss of
    the last pass."""
    import torch

    policy = model.policy
    policy.set_training_mode(True)
    n = len(labels)
    last = []
    for _ in range(epochs):
        last = []
        order = rng.permutation(n)
        for start in range(0, n, batch_size):
            idx = order[start:start + batch_size]
            obs, _ = policy.obs_to_tensor({k: v[idx] for k, v in observations.items()})
            actions = torch.as_tensor(labels[idx], device=policy.device)
            _, log_prob, _ = policy.evaluate_actions(obs, actions)
            loss = -log_prob.mean()
            policy.optimizer.zero_grad()
            loss.backward()
            torch.nn.utils.clip_grad_norm_(policy.parameters(), 0.5)
            policy.optimizer.step()
            last.append(loss.item())
    policy.set_training_mode(False)
    return float(np.mean(last))


def dagger(model, env_id: str, env_kwargs: dict, iterations: int, episodes: int,
           epochs: int, seed: int, batch_size: int = 128,
           progress: bool = True) -> ImitationResult:
    """Warm-start ``model`` (an SB3 PPO model) on ``env_id`` by DAgger with the oracle;
    episodes use seeds ``seed, seed + 1, ...`` (training seeds, never the suite's)."""
    if iterations < 1 or episodes < 1 or epochs < 1:
        raise ValueError(f"imitation needs iterations, episodes and epochs >= 1, got "
                         f"{iterations}, {episodes}, {epochs}")
    env = gym.make(env_id, **env_kwargs)
    oracle = homing_baselines.make("oracle")
    prepare_policy(oracle, env)
    rng = np.random.default_rng(seed)
    result = ImitationResult()
    data: dict[str, list] = {k: [] for k in env.observation_space.spaces}
    labels: list = []
    try:
        for i in tqdm(range(iterations), desc="imitation (DAgger)", disable=not progress):
            beta = 0.5 ** i
            obs, lab, agreement = collect(env, oracle, model, beta, episodes,
                                          seed + i * episodes, rng)
            for key in data:
                data[key].extend(obs[key])
            labels.extend(lab)
            arrays = {k: np.asarray(v) for k, v in data.items()}
            loss = fit(model, arrays, np.asarray(labels), epochs, batch_size, rng)
            result.beta.append(beta)
            result.samples.append(len(labels))
            result.loss.append(loss)
            result.agreement.append(agreement)
    finally:
        env.close()
    return result
