"""``infomax``: Infomax route following, Baddeley et al. (2012).

Baddeley, Graham, Husbands & Philippides 2012 (PLoS Comput Biol 8(1): e1002336) train a
two-layer network on the route's views and use its *novelty* as the (un)familiarity of a
scanned view. The network and its rule are the Infomax of Bell & Sejnowski (1995, Neural
Computation 7) as Lulham, Bogacz, Vogt & Brown (2011, Neural Computation 23, "An infomax
algorithm can perform both familiarity discrimination and feature extraction in a single
network") use it to tell familiar from novel stimuli:

* activation ``h = W x`` (``x`` the view, ``N`` inputs, ``N`` output units as the paper's
  network), output ``y = tanh(h)``;
* learning, each training view once, in travel order:
  ``dW = eta / N (W - (y + h) h^T W)``, i.e. ``dw_ij = eta/N (w_ij - (y_i + h_i)
  sum_k h_k w_kj)`` (the authors' training code, ``infomax_learn2``, writes it
  ``W = W + lrate/N * (I - (y+u) u') * W``, ``u = W x``; we compute ``h^T W`` first, an
  ``N``-vector, instead of the ``N x N`` matrix ``I - (y+h) h^T``: the same update, ``N``
  times cheaper);
* novelty of a view: the summed absolute activation ``sum_i |h_i|``; the most familiar
  scanned heading is the one of least novelty.

Our choices (see also :mod:`homing_baselines.familiarity` for the scan, step and stop):

* **Initial weights**: seeded standard normal, each row scaled to unit standard
  deviation (as the authors' ``infomax_init2``), ``seed`` = 0: the same network for every
  episode, so that an episode depends on its seed only through the env.
* **Input**: each view normalised to zero mean and unit variance (the shared
  :func:`~homing_baselines.familiarity.normalised`), ``N`` = 24 x 128 = 3072 inputs for
  the default panorama and ``levels`` (the paper's network: 1530).
* **Learning rate** ``learning_rate`` = 0.0005, half the authors' code's starting value
  0.001 (their code lowers the rate by 1 % after each blow-up and learns again; here a
  blow-up is a ``FloatingPointError`` naming the parameter). At 3072 inputs 0.001 blew
  up on the validation routes; 0.0005 was chosen there (natural routes' last stop within
  the radius: 97 % of 30, 87 % at 0.0002).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from homing_baselines.familiarity import FamiliarityController, normalised
from homing_gym.validation import require_number


class InfomaxNetwork:
    """The Infomax familiarity network (module doc): ``n_inputs`` inputs and as many
    outputs, initial weights from ``seed``, trained by :meth:`learn`."""

    def __init__(self, n_inputs: int, learning_rate: float, seed: int = 0):
        rng = np.random.default_rng(seed)
        w = rng.standard_normal((n_inputs, n_inputs))
        self.weights = w / w.std(axis=1, keepdims=True)
        self.learning_rate = float(learning_rate)

    def learn(self, views: np.ndarray) -> None:
        """One pass over ``views`` ``(K, h, w)`` in order: ``dW = eta/N (W - (y + h) h^T W)``
        with ``h = W x``, ``y = tanh(h)``; ``FloatingPointError`` if the weights blow up."""
        w = self.weights.copy()
        rate = self.learning_rate / w.shape[1]
        for x in normalised(views):
            h = w @ x
            y = np.tanh(h)
            hw = h @ w
            w *= 1 + rate                           # in place: W + eta/N W ...
            w -= np.outer(rate * (y + h), hw)       # ... - eta/N (y + h) h^T W
            if not np.all(np.isfinite(w)):
                raise FloatingPointError(f"infomax: the weights blew up with learning_rate "
                                         f"{self.learning_rate!r}; use a smaller one")
        self.weights = w

    def unfamiliarity(self, images: np.ndarray) -> np.ndarray:
        """``(S,)``: the novelty ``sum_i |h_i|`` of each of ``images`` ``(S, h, w)``."""
        return np.abs(normalised(images) @ self.weights.T).sum(axis=1)


@dataclass
class InfomaxController(FamiliarityController):
    """Infomax (Baddeley et al. 2012): scan, then step towards the heading of least
    novelty of the network trained on the route's views. ``learning_rate``: ``eta`` of
    the rule (> 0); ``seed``: of the initial weights; the other parameters:
    :class:`~homing_baselines.familiarity.FamiliarityController`."""

    learning_rate: float = 0.0005
    seed: int = 0

    def validate(self) -> None:
        super().validate()
        require_number("infomax: learning_rate", self.learning_rate, 0, 1, low_open=True)
        require_number("infomax: seed", self.seed, 0, 2**32 - 1, integer=True)

    def make_memory(self, views: np.ndarray) -> InfomaxNetwork:
        network = InfomaxNetwork(views[0].size, self.learning_rate, self.seed)
        network.learn(views)
        return network
