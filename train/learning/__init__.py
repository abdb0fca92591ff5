"""Learned policies: PPO training (``homing-train``), pose-pair pretraining, imitation of
the oracle, feature extractors, and shipping a trained policy with its record."""
