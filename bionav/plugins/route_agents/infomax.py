"""``infomax`` route agent (Baddeley, Graham, Husbands & Philippides 2012, doi:10.1371/journal.pcbi.1002336)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bionav.plugins.route_agents import RouteAgent
from bionav.validation import bounded


@dataclass
class InfomaxConfig:
    """Parameters of the infomax network.

    Attributes
    ----------
    learning_rate : float
        ``eta`` of the weight update. Ardin et al. 2016 (doi:10.1371/journal.pcbi.1004683, Methods:
        "closely following [Baddeley et al. 2012] except with a much higher learning rate") use
        ``eta = 1.1`` on normalised intensities of the 36 x 10 pixels, one presentation per view;
        1.1 is the default here, on views normalised to zero mean and unit length. 0.01 is
        Baddeley et al.'s rate (on their input scale) and the benchmark navbench's default; on
        unit-length inputs it barely moves the random weights in one pass (docs/worlds.md has both).
    hidden_ratio : float
        Hidden units per input pixel (1: as many as pixels, the paper's choice).
    epochs : int
        Passes over the training views (the paper: 1, each view seen once).
    """

    learning_rate: float = bounded(1.1, gt=0.0, le=10.0)
    hidden_ratio: float = bounded(1.0, gt=0.0, le=10.0)
    epochs: int = bounded(1, ge=1, le=1000)


class Infomax(RouteAgent):
    """A single-layer infomax network trained on the route views; unfamiliarity ``sum |W x|``.

    Inputs ``x``: each view standardised (zero mean, unit std) and scaled to
    unit length (``/ sqrt(pixels)``), so that ``h = W x`` stays of order 1 for
    the unit-variance initial weights (BoB's navbench scales [0, 1] images by
    0.1 for the same reason: tanh out of saturation, a stable update).
    """

    Config = InfomaxConfig

    def train(self, views: np.ndarray) -> None:
        from bionav.homing.familiarity import infomax_initial_weights, infomax_train

        x = _inputs(views)
        n = x.shape[1]
        w = infomax_initial_weights(n, max(1, int(round(self.config.hidden_ratio * n))), rng=self.rng)
        for _ in range(self.config.epochs):
            w = infomax_train(w, x, learning_rate=self.config.learning_rate)
        self.weights = w

    def unfamiliarity(self, views: np.ndarray) -> np.ndarray:
        from bionav.homing.familiarity import infomax_unfamiliarity

        return infomax_unfamiliarity(self.weights, _inputs(views))


def _inputs(views: np.ndarray) -> np.ndarray:
    from bionav.homing.familiarity import standardise

    x = standardise(views)
    return x / np.sqrt(x.shape[1])
