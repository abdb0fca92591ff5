"""Fixed, distinct method colours of the comparison plots."""

import homing_baselines
from homing_train.harness.policies import shipped_policies
from homing_train.harness.palette import HOME_MARK, START_MARK, method_color, method_color_255


def test_every_registered_method_has_its_own_fixed_colour():
    names = homing_baselines.available() + sorted(shipped_policies())
    colours = [method_color(n) for n in names]
    assert len(set(colours)) == len(names)
    # the same colours in every process and session (a user's method by a CRC of its
    # name, not Python's salted hash)
    assert method_color_255("warping") == (86, 180, 233)               # Okabe-Ito sky blue
    assert method_color_255("ppo_procedural_long") == (118, 42, 131)   # dark purple
    assert method_color_255("my_controller") == (221, 204, 119)        # a spare: sand
    # a user's method never takes the colour of one of the package's
    spares = {method_color(f"method{i}") for i in range(100)}
    assert len(spares) > 1 and spares.isdisjoint(colours)
    assert {HOME_MARK, START_MARK}.isdisjoint({method_color_255(n) for n in names})
