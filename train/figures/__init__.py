"""Reproducible figure and table scripts of the method pages (``python -m
homing_train.figures.NAME``); commands, not library API.

The tables of the method pages were measured with homing-gym 0.1's defaults, TinyRenderer
and physics steps of 1/240 s; every figure script pins them (:data:`MEASURED_WITH`), so
its printed command still reproduces its table under 0.2's defaults (the ray caster,
1/120 s). Re-measuring a page with the new defaults means changing a script's pin and the
page together."""

from homing_train.harness.protocols import V1_SIMULATION

#: The renderer and physics of the method pages' tables (homing-gym 0.1's defaults).
MEASURED_WITH = V1_SIMULATION
