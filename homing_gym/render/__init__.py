"""Rendering: the ray caster and its shading, shadows, the panoramic camera, perspective
views (PyBullet's TinyRenderer in ``panorama`` and ``perspective``) and the top-down map.

Imports only :mod:`homing_gym.scenes` and the shared helpers, never the simulator or the
env core (``tests/test_architecture.py``)."""
