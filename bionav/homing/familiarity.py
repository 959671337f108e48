"""Scene-familiarity route memories: perfect memory, infomax, the mushroom body.

A familiarity agent stores the views seen along a training route and, when
tested, rates every candidate view (one per heading of a scan) by its
*unfamiliarity*; the agent walks towards the least unfamiliar heading
(Baddeley, Graham, Husbands & Philippides 2012, "A model of ant route
navigation driven by scene familiarity", PLoS Comput. Biol. 8(1), e1002336,
doi:10.1371/journal.pcbi.1002336).

Conventions: views are arrays of shape ``(N, H, W)`` (or flattened
``(N, P)``), float grey values (any scale; the agents' own preprocessing
decides); unfamiliarity is dimensionless, lower = more familiar. Random
connectivity and initial weights come from an explicit
:class:`numpy.random.Generator` (no hidden random state).
"""

from __future__ import annotations

import numpy as np


def _flat(views: np.ndarray) -> np.ndarray:
    v = np.asarray(views, np.float64)
    if v.ndim == 1:
        v = v[None]
    return v.reshape(v.shape[0], -1)


def view_differences(views: np.ndarray, snapshots: np.ndarray) -> np.ndarray:
    """Mean squared pixel difference of every view against every snapshot.

    Parameters
    ----------
    views : ndarray, shape (N, H, W) or (N, P)
    snapshots : ndarray, shape (K, H, W) or (K, P)

    Returns
    -------
    ndarray, shape (N, K)
        ``D[n, k] = mean((views[n] - snapshots[k])**2)`` (no rotation: the
        views of a scan are rendered at their own headings).
    """
    v = _flat(views)
    s = _flat(snapshots)
    if v.shape[1] != s.shape[1]:
        raise ValueError(f"views have {v.shape[1]} pixels, snapshots {s.shape[1]}")
    d = (v ** 2).sum(1)[:, None] + (s ** 2).sum(1)[None] - 2.0 * v @ s.T
    return np.maximum(d, 0.0) / v.shape[1]


def standardise(views: np.ndarray) -> np.ndarray:
    """Every view to zero mean and unit standard deviation (constant views to zeros), shape ``(N, P)``."""
    v = _flat(views)
    sd = v.std(axis=1, keepdims=True)
    return (v - v.mean(axis=1, keepdims=True)) / np.where(sd > 0, sd, 1.0)


def infomax_initial_weights(n_inputs: int, n_hidden: int, *, rng: np.random.Generator) -> np.ndarray:
    """Initial infomax weights: uniform in [-0.5, 0.5], each unit's row to zero mean and unit std.

    Returns
    -------
    ndarray, shape (n_hidden, n_inputs)
    """
    w = rng.uniform(-0.5, 0.5, size=(int(n_hidden), int(n_inputs)))
    return standardise(w)


def infomax_train(weights: np.ndarray, inputs: np.ndarray, *, learning_rate: float) -> np.ndarray:
    """Train an infomax network on views, each presented once in order (Baddeley et al. 2012).

    For each input ``x`` (standardised view, length ``N``): ``h = W x``,
    ``y = tanh(h)`` and ``W <- W + (eta / N) (W - (y + h) (h^T W))``
    (doi:10.1371/journal.pcbi.1002336; the natural-gradient infomax rule of Bell & Sejnowski).

    Parameters
    ----------
    weights : ndarray, shape (M, N)
    inputs : ndarray, shape (K, N)
        Standardised views (:func:`standardise`).
    learning_rate : float
        ``eta``.

    Returns
    -------
    ndarray, shape (M, N)
        The trained weights (a new array).
    """
    w = np.array(weights, np.float64)
    x = np.asarray(inputs, np.float64)
    n = w.shape[1]
    for xi in x:
        h = w @ xi
        y = np.tanh(h)
        w += (learning_rate / n) * (w - np.outer(y + h, h @ w))
    return w


def infomax_unfamiliarity(weights: np.ndarray, inputs: np.ndarray) -> np.ndarray:
    """Infomax decision value ``sum_i |h_i|`` with ``h = W x`` per input, shape ``(K,)`` (lower = more familiar)."""
    return np.abs(np.asarray(inputs, np.float64) @ np.asarray(weights, np.float64).T).sum(axis=1)


def kenyon_connections(n_inputs: int, n_kc: int, inputs_per_kc: int, *, rng: np.random.Generator) -> np.ndarray:
    """Random PN-to-KC connectivity: each Kenyon cell samples ``inputs_per_kc`` distinct PNs.

    Returns
    -------
    ndarray, shape (n_kc, inputs_per_kc), int
        PN indices of each KC.
    """
    if inputs_per_kc > n_inputs:
        raise ValueError(f"inputs_per_kc={inputs_per_kc} exceeds the {n_inputs} inputs")
    keys = rng.random((int(n_kc), int(n_inputs)))
    return np.argpartition(keys, int(inputs_per_kc) - 1, axis=1)[:, : int(inputs_per_kc)]


def kenyon_matrix(connections: np.ndarray, n_inputs: int):
    """The PN-to-KC connectivity as a sparse 0/1 matrix, shape ``(n_inputs, n_kc)`` (``scipy.sparse`` CSC).

    ``inputs @ kenyon_matrix(c, n)`` equals ``inputs[:, c].sum(axis=2)``, about 6 times faster for 20,000 KCs
    (column-compressed: each KC's column holds its inputs, the product runs KC by KC).
    """
    import scipy.sparse as sp

    c = np.asarray(connections)
    n_kc, per = c.shape
    return sp.csc_matrix((np.ones(c.size), (c.ravel(), np.repeat(np.arange(n_kc), per))), shape=(int(n_inputs), n_kc))


def kenyon_drive(inputs: np.ndarray, connections) -> np.ndarray:
    """Summed PN input of every Kenyon cell, shape ``(K, n_kc)``.

    Parameters
    ----------
    inputs : ndarray, shape (K, N)
        PN activity per view.
    connections : ndarray, shape (n_kc, c), int, or sparse matrix, shape (N, n_kc)
        :func:`kenyon_connections`, or the same as :func:`kenyon_matrix` (faster).
    """
    x = np.asarray(inputs, np.float64)
    if isinstance(connections, np.ndarray):
        return x[:, connections].sum(axis=2)
    return np.asarray(x @ connections)


def kenyon_thresholds(drive: np.ndarray, *, floor: float = 0.1) -> tuple[np.ndarray, np.ndarray]:
    """Per-KC firing thresholds adapted to the training views: the mean and std of each KC's drive over them.

    A KC whose drive hardly varies over the training views gets the std ``floor`` x the
    median std of all KCs, so that a tiny variation does not make it fire on everything.

    Parameters
    ----------
    drive : ndarray, shape (K, n_kc)
        :func:`kenyon_drive` of the K training views.

    Returns
    -------
    centre, scale : ndarray, shape (n_kc,)
        ``(drive - centre) / scale`` is what :func:`kenyon_activity` ranks.
    """
    d = np.asarray(drive, np.float64)
    centre = d.mean(axis=0)
    sd = d.std(axis=0)
    positive = sd[sd > 0]
    small = floor * float(np.median(positive)) if len(positive) else 1.0
    return centre, np.maximum(sd, small)


def kenyon_activity(inputs: np.ndarray, connections, *, n_active: int,
                    thresholds: tuple[np.ndarray, np.ndarray] | None = None) -> np.ndarray:
    """Binary Kenyon-cell code: the ``n_active`` KCs with the largest summed PN input fire.

    Parameters
    ----------
    inputs : ndarray, shape (K, N)
        PN activity per view.
    connections : ndarray, shape (n_kc, c), int, or sparse matrix, shape (N, n_kc)
        :func:`kenyon_connections`, or the same as :func:`kenyon_matrix` (faster).
    thresholds : (centre, scale), optional
        Per-KC adapted thresholds (:func:`kenyon_thresholds`): the KCs with the largest
        ``(drive - centre) / scale`` fire instead (one shared threshold when None).
    n_active : int
        KCs firing per view (k-winners-take-all; Ardin et al. 2016 tuned their
        spiking network to about 200 of 20,000). KCs whose drive ties with the
        ``n_active``-th largest fire in the order of their index until ``n_active`` fire.

    Returns
    -------
    ndarray, shape (K, n_kc), bool
        Exactly ``min(n_active, n_kc)`` True per row.
    """
    drive = kenyon_drive(inputs, connections)
    if thresholds is not None:
        centre, scale = thresholds
        drive -= centre  # in place: the same values as (drive - centre) / scale, without two more arrays
        drive /= scale
    n_kc = drive.shape[1]
    k = int(min(max(n_active, 1), n_kc))
    kth = np.partition(drive, n_kc - k, axis=1)[:, n_kc - k][:, None]  # the k-th largest drive of each view
    fire = drive >= kth
    over = np.flatnonzero(fire.sum(axis=1) > k)  # rows where drives tie with the k-th: fire in index order
    if len(over):
        rows = drive[over]
        above = rows > kth[over]
        tied = rows == kth[over]
        fire[over] = above | (tied & (np.cumsum(tied, axis=1) <= k - above.sum(axis=1, keepdims=True)))
    return fire


def mushroom_body_train(kc_to_en: np.ndarray, active: np.ndarray, *, depression: float) -> np.ndarray:
    """Depress the KC-to-EN weights of every KC active in a training view (Ardin et al. 2016).

    ``w <- w * (1 - depression)`` once per training view in which the KC fires
    (``depression = 1``: one-shot learning, the weight drops to 0).

    Parameters
    ----------
    kc_to_en : ndarray, shape (n_kc,)
    active : ndarray, shape (K, n_kc), bool

    Returns
    -------
    ndarray, shape (n_kc,)
    """
    count = np.asarray(active, bool).sum(axis=0)
    return np.asarray(kc_to_en, np.float64) * (1.0 - float(depression)) ** count


def mushroom_body_novelty(kc_to_en: np.ndarray, active: np.ndarray) -> np.ndarray:
    """Extrinsic-neuron output per view: ``sum`` of the weights of the active KCs, shape ``(K,)`` (lower = more familiar).

    With weights of 0 and 1 only (one-shot depression) the sum is the count of active KCs of weight 1, counted
    as such (the same numbers, exact in either form).
    """
    w = np.asarray(kc_to_en, np.float64)
    a = np.asarray(active)
    if a.dtype == bool and np.all((w == 0.0) | (w == 1.0)):
        return np.count_nonzero(a & (w == 1.0), axis=1).astype(np.float64)
    return a.astype(np.float64) @ w


__all__ = ["infomax_initial_weights", "infomax_train", "infomax_unfamiliarity", "kenyon_activity",
           "kenyon_connections", "kenyon_drive", "kenyon_matrix", "kenyon_thresholds", "mushroom_body_novelty",
           "mushroom_body_train", "standardise", "view_differences"]
