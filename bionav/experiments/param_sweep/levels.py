"""The configurations one parameter-homing job evaluates, and their measures computed together.

:func:`sweep_levels` lists a job's configurations (every ring count ``R`` or number of Fourier
coefficients ``K``); :func:`evaluate_levels` computes AAE*, MAE* and RR* of all of them at once
(thesis 3.2, :mod:`bionav.evaluation`), equal to :func:`evaluate_configuration`, the plain path of
one configuration.
"""

from __future__ import annotations

import dataclasses
import time
from typing import Any, Sequence

import numpy as np

from bionav.db.database import ImageDatabase
from bionav.evaluation.pairs import home_vector_matrix


def sweep_levels(signature_cls: type, *, rings: Sequence[int], n_coeffs: Sequence[int]) -> list[dict[str, int]]:
    """The configurations one job evaluates: one dict of signature parameters each.

    DFT signatures (a ``n_coeffs`` parameter) vary ``K`` over ``n_coeffs``;
    ring signatures (a ``rings`` parameter) vary ``R`` over ``rings``; a
    signature with neither ([image]) has one configuration ``{}``.
    """
    names = {f.name for f in dataclasses.fields(signature_cls.Config)}
    if "n_coeffs" in names:
        return [{"n_coeffs": int(k)} for k in n_coeffs]
    if "rings" in names:
        return [{"rings": int(r)} for r in rings]
    return [{}]


def evaluate_configuration(homing, db: ImageDatabase, *, step_length: float = 0.5, success_radius: float = 1.0):
    """AAE*/MAE*/RR* of one parameter-homing configuration on one database.

    The plain per-configuration path (the reference of :func:`evaluate_levels`,
    which the experiment runs): signatures are computed once per image; home
    vectors of all pairs by the all-pairs runner through the method's batch
    path (:meth:`ParameterHoming.all_pairs_angles`); agents row by row
    (:func:`bionav.evaluation.agent.run_agents`) and measures as thesis 3.2.

    Returns
    -------
    measures : bionav.evaluation.measures.QualityMeasures
    hv : HomeVectorMatrix
        With ``prepare_s`` set to the per-image time.
    """
    from bionav.evaluation.agent import evaluate_agents
    from bionav.evaluation.measures import angular_errors, ideal_home_angles, quality_measures

    t0 = time.perf_counter()
    use_raw = db.raw is not None and getattr(homing.signature, "uses_raw", False)
    prepared = [homing.prepare(img, raw=db.raw(i) if use_raw else None) for i, img in enumerate(db.images)]
    prepare_s = time.perf_counter() - t0
    hv = home_vector_matrix(homing, db, prepared=(prepared, prepared))
    hv = dataclasses.replace(hv, prepare_s=prepare_s)
    ae = angular_errors(hv.angles, ideal_home_angles(db.positions, db.positions))
    success, _ = evaluate_agents(db, hv, step_length=step_length, success_radius=success_radius, batch=False)
    return quality_measures(ae, success), hv


def evaluate_levels(
    homing_cls: type,
    homing_cfg: Any,
    signature_cls: type,
    signature_cfg: Any,
    levels: Sequence[dict[str, int]],
    db: ImageDatabase,
    *,
    step_length: float = 0.5,
    success_radius: float = 1.0,
):
    """AAE*/MAE*/RR* of every configuration of one job, sharing the work between them.

    The same measures as :func:`evaluate_configuration` per level, computed
    together: DFT signatures (``coefficient_index``) are computed once per
    image with the largest ``K`` and the potentials (or matched-filter
    gradients) of every ``K`` are partial sums over the coefficients; other
    signatures are computed per level. The agent trials of all levels run in
    one compiled batch (:func:`bionav.evaluation.agent.agent_success`).

    Returns
    -------
    homings : list of ParameterHoming
        One per level.
    measures : list of QualityMeasures
        One per level.
    ms_per_home_vector : float
        Wall time of the whole job per configuration and home vector, ms.
    """
    from bionav.evaluation.agent import agent_success
    from bionav.evaluation.measures import angular_errors, ideal_home_angles, quality_measures
    from bionav.evaluation.pairs import neighbour_table

    t0 = time.perf_counter()
    homings = [
        homing_cls(homing_cfg, geometry=db.geometry, signature=signature_cls(dataclasses.replace(signature_cfg, **lv)))
        for lv in levels
    ]
    use_raw = db.raw is not None and getattr(homings[0].signature, "uses_raw", False)
    headings, neighbours = db.headings, neighbour_table(db)
    ks = [lv.get("n_coeffs") for lv in levels]
    nested = len(levels) > 1 and None not in ks and all(hasattr(h.signature, "coefficient_index") for h in homings)
    if nested:
        top = homings[int(np.argmax(ks))]
        prepared = [top.prepare(img, raw=db.raw(i) if use_raw else None) for i, img in enumerate(db.images)]
        shape = np.asarray(db.images[0]).shape[:2]
        angles = top.all_pairs_angles_by_coefficients(prepared, n_coeffs=ks, image_shape=shape, headings=headings,
                                                      neighbours=neighbours)
    else:
        stack = []
        for homing in homings:
            prepared = [homing.prepare(img, raw=db.raw(i) if use_raw else None) for i, img in enumerate(db.images)]
            stack.append(homing.all_pairs_angles(prepared, headings=headings, neighbours=neighbours))
        angles = np.stack(stack)
    ideal = ideal_home_angles(db.positions, db.positions)
    angles[:, np.isnan(ideal)] = np.nan  # a snapshot's own cell (as the all-pairs runner)
    success = agent_success(angles, db.positions, db.positions, grid_shape=db.grid_shape, step_length=step_length,
                            success_radius=success_radius)
    measures = [quality_measures(angular_errors(a, ideal), ok) for a, ok in zip(angles, success)]
    n_pairs = int(np.sum(~np.isnan(ideal)))
    ms = 1e3 * (time.perf_counter() - t0) / max(n_pairs * len(levels), 1)
    return homings, measures, ms
