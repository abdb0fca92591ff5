"""Fixed, distinct method colours and the Wilson intervals of the comparison plots."""

import pytest

import homing_baselines
from homing_train.harness.compare import wilson_interval
from homing_train.harness.palette import HOME_MARK, START_MARK, method_color, method_color_255


def test_every_registered_method_has_its_own_fixed_colour():
    names = homing_baselines.available() + ["ppo_localhoming"]
    colours = [method_color(n) for n in names]
    assert len(set(colours)) == len(names)
    assert method_color("warping") == method_color("warping")
    assert method_color("my_controller") == method_color("my_controller")
    assert {HOME_MARK, START_MARK}.isdisjoint({method_color_255(n) for n in names})


def test_wilson_interval_against_hand_computed_values():
    # k = 5 of n = 10: centre 0.5, half-width z sqrt(p(1-p)/n + z^2/4n^2) / (1 + z^2/n)
    assert wilson_interval(5, 10) == pytest.approx((0.2366, 0.7634), abs=1e-3)
    assert wilson_interval(0, 10) == pytest.approx((0.0, 0.2775), abs=1e-3)
    assert wilson_interval(10, 10) == pytest.approx((0.7225, 1.0), abs=1e-3)
