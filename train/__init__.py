"""homing_train: scoring, learning and paper figures on top of :mod:`homing_gym`.

Installed as ``homing_train`` from the ``train/`` folder. One subpackage per job:

* :mod:`homing_train.harness`: the evaluation harness (episodes, metrics, comparison,
  suites, homing fields, demo) and the one rollout loop they share;
* :mod:`homing_train.learning`: PPO training, pretraining, imitation, feature extractors,
  shipping policies;
* :mod:`homing_train.figures`: the scripts that reproduce each paper page's figures and
  tables (commands, not library API).
"""

#: The env the commands (``homing-eval``, ``homing-train``, ...) use unless told otherwise.
DEFAULT_ENV = "homing_gym/LocalHoming-v0"
