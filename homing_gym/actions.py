"""The discrete action set of ``action_type="discrete"``: one table for env and controllers."""

from __future__ import annotations

from enum import IntEnum


class DiscreteAction(IntEnum):
    """``Discrete(4)`` actions; :attr:`command` is the normalised ``(forward, yaw rate)``
    held for one control period (yaw counter-clockwise positive)."""

    FORWARD = 0
    TURN_LEFT = 1
    TURN_RIGHT = 2
    STOP = 3

    @property
    def command(self) -> tuple[float, float]:
        return _COMMANDS[self]


_COMMANDS = {DiscreteAction.FORWARD: (1.0, 0.0), DiscreteAction.TURN_LEFT: (0.0, 1.0),
             DiscreteAction.TURN_RIGHT: (0.0, -1.0), DiscreteAction.STOP: (0.0, 0.0)}
