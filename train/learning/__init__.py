"""Learned policies: PPO training (``homing-train``), pose-pair pretraining, imitation of
the oracle, feature extractors, and shipping a trained policy with its record."""

#: Names of the features extractors (:mod:`homing_train.learning.extractor`).
EXTRACTORS = ("panorama", "band", "align", "combined")
