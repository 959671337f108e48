"""``mushroom_body`` route agent (Ardin, Peng, Mangan, Lagogiannis & Webb 2016, doi:10.1371/journal.pcbi.1004683)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bionav.plugins.route_agents import RouteAgent
from bionav.validation import bounded


@dataclass
class MushroomBodyConfig:
    """Parameters of the mushroom body (wiring: the paper's network).

    Attributes
    ----------
    n_kc : int
        Kenyon cells (20,000 in the paper; one input neuron per pixel, 360 for 36 x 10).
    inputs_per_kc : int
        Projection neurons sampled by each KC (10, the paper's).
    n_active : int
        KCs firing per view (sparsity; the paper's spiking network was tuned to about
        200 of 20,000, 1 %; here exactly the ``n_active`` highest-ranked fire).
    kc_threshold : str
        How KCs are ranked. ``per_kc`` (default): each KC's threshold adapts to its own drive
        over the training views (its drive z-scored by its mean and std there,
        :func:`bionav.homing.familiarity.kenyon_thresholds`), so every KC is about equally
        likely to fire; ``shared``: one threshold for all, the raw summed input ranks (the
        paper's rate equivalent, and issue 30's model).
    depression : float
        Fraction of a KC-to-EN weight removed each time its KC fires during
        training (1: one-shot learning, the weight drops to 0; the paper's rule).
    """

    n_kc: int = bounded(20_000, ge=1, le=1_000_000)
    inputs_per_kc: int = bounded(10, ge=1, le=10_000)
    n_active: int = bounded(200, ge=1, le=1_000_000)
    kc_threshold: str = bounded("per_kc", choices=("per_kc", "shared"))
    depression: float = bounded(1.0, gt=0.0, le=1.0)


class MushroomBody(RouteAgent):
    """PNs (pixels) -> sparse Kenyon cells -> one extrinsic neuron whose output is the novelty.

    A rate version of Ardin et al.'s spiking model: PN activity is the pixel intensity; each KC
    sums ``inputs_per_kc`` random PNs; the ``n_active`` highest-ranked KCs fire (binary); every
    KC-to-EN weight starts at 1 and is depressed when its KC fires on a training view; the EN
    output (the sum of the active KCs' weights) is the unfamiliarity. Training first adapts the
    KC thresholds (``kc_threshold=per_kc``), then presents every training view once.
    """

    Config = MushroomBodyConfig

    def train(self, views: np.ndarray) -> None:
        from bionav.errors import UserError
        from bionav.homing.familiarity import (
            kenyon_activity,
            kenyon_connections,
            kenyon_drive,
            kenyon_matrix,
            kenyon_thresholds,
            mushroom_body_train,
        )

        x = np.asarray(views, np.float64).reshape(len(views), -1)
        c = self.config
        if c.inputs_per_kc > x.shape[1]:
            raise UserError(f"route_agent mushroom_body: inputs_per_kc={c.inputs_per_kc} exceeds the {x.shape[1]} "
                            "pixels of a view; use a smaller inputs_per_kc.")
        self.connections = kenyon_matrix(kenyon_connections(x.shape[1], c.n_kc, c.inputs_per_kc, rng=self.rng), x.shape[1])
        self.thresholds = kenyon_thresholds(kenyon_drive(x, self.connections)) if c.kc_threshold == "per_kc" else None
        active = kenyon_activity(x, self.connections, n_active=c.n_active, thresholds=self.thresholds)
        self.kc_to_en = mushroom_body_train(np.ones(c.n_kc), active, depression=c.depression)

    def unfamiliarity(self, views: np.ndarray) -> np.ndarray:
        from bionav.homing.familiarity import kenyon_activity, mushroom_body_novelty

        x = np.asarray(views, np.float64).reshape(len(views), -1)
        active = kenyon_activity(x, self.connections, n_active=self.config.n_active, thresholds=self.thresholds)
        return mushroom_body_novelty(self.kc_to_en, active)
