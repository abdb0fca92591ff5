"""Fixed, distinct method colours of the comparison plots."""

import homing_baselines
from homing_train.harness.policies import shipped_policies
from homing_train.harness.palette import HOME_MARK, START_MARK, method_color, method_color_255


def test_every_registered_method_has_its_own_fixed_colour():
    names = homing_baselines.available() + sorted(shipped_policies())
    colours = [method_color(n) for n in names]
    assert len(set(colours)) == len(names)
    assert method_color("warping") == method_color("warping")
    assert method_color("my_controller") == method_color("my_controller")
    assert {HOME_MARK, START_MARK}.isdisjoint({method_color_255(n) for n in names})
