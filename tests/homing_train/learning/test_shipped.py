"""The shipped PPO policy (``train/shipped/``): it loads, matches the env, and homes."""

import pytest
import yaml

from homing_train.harness.evaluate import DEFAULT_ENV, evaluate
from homing_train.harness.policies import shipped_policies

SHIPPED = shipped_policies()


def test_a_policy_is_shipped_with_its_config_and_curve():
    assert SHIPPED, "train/shipped/ holds no policy"
    for name, shipped in SHIPPED.items():
        assert shipped.path.stat().st_size < 10 * 2**20, name
        assert shipped.path.with_suffix(".yml").is_file(), name
        assert shipped.path.with_name(f"{name}_curve.png").is_file(), name


def training_scenes(shipped) -> list[str]:
    """The scenes a shipped policy was trained in (its ``.yml``'s run config; the env's
    default ``arena`` when the run named none)."""
    config = yaml.safe_load(shipped.path.with_suffix(".yml").read_text())["config"]
    scene = config["env_kwargs"].get("scene", "arena")
    return scene if isinstance(scene, list) else [scene]


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(SHIPPED))
def test_shipped_policy_reaches_home_in_half_of_10_held_out_episodes_of_its_training_worlds(name):
    """What it was trained for: 10 episodes split over its training scenes, seeds from
    1,000,000 (procedural worlds it never trained in; the arena's homes and starts are
    new). How it does in worlds of other kinds is the protocols' job (unseen, local-common)."""
    shipped = SHIPPED[name]
    scenes = training_scenes(shipped)
    successes = 0
    for i, scene in enumerate(scenes):
        n = 10 // len(scenes) + (i < 10 % len(scenes))
        result = evaluate(str(shipped.path), DEFAULT_ENV, episodes=n, seed=1_000_000,
                          env_kwargs={**shipped.env_kwargs, "scene": scene},
                          params=shipped.params, workers=1)
        successes += sum(r.success for r in result.episodes)
    assert successes >= 5, (name, scenes, successes)
