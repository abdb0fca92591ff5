"""The shipped PPO policy (``train/shipped/``): it loads, matches the env, and homes."""

import pytest

from homing_train.harness.evaluate import DEFAULT_ENV, evaluate
from homing_train.harness.policies import shipped_policies

SHIPPED = shipped_policies()


def test_a_policy_is_shipped_with_its_config_and_curve():
    assert SHIPPED, "train/shipped/ holds no policy"
    for name, shipped in SHIPPED.items():
        assert shipped.path.stat().st_size < 10 * 2**20, name
        assert shipped.path.with_suffix(".yml").is_file(), name
        assert shipped.path.with_name(f"{name}_curve.png").is_file(), name


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(SHIPPED))
def test_shipped_policy_reaches_home_in_half_of_10_episodes(name):
    shipped = SHIPPED[name]
    result = evaluate(str(shipped.path), DEFAULT_ENV, episodes=10, seed=0,
                      env_kwargs=shipped.env_kwargs, params=shipped.params, workers=1)
    assert sum(r.success for r in result.episodes) >= 5, result.summary
