"""The simulated world: the PyBullet client with the scene's bodies and the robot.

Imports :mod:`homing_gym.render`, :mod:`homing_gym.scenes` and the shared helpers, never
the env core (``tests/test_architecture.py``)."""
