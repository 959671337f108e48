"""A database exported and read back through db=folder gives the same AAE*/MAE*/RR* as read directly."""

from __future__ import annotations

import numpy as np
import pytest
from helpers import round_room

from bionav.db.compose import compose_database
from bionav.db.database import ImageDatabase
from bionav.db.export import export_database
from bionav.db.loading import load_database
from bionav.evaluation.agent import evaluate_agents
from bionav.evaluation.measures import angular_errors, ideal_home_angles, quality_measures
from bionav.evaluation.pairs import home_vector_matrix


def measures_of(db: ImageDatabase, snapshot_index=None):
    from bionav.plugins.homing.mfdid import MfdidConfig, MfdidHoming

    method = MfdidHoming(MfdidConfig(), geometry=db.geometry)
    hv = home_vector_matrix(method, db, snapshot_index=snapshot_index)
    ae = angular_errors(hv.angles, ideal_home_angles(db.positions[hv.snapshot_index], db.positions))
    success, _ = evaluate_agents(db, hv, step_length=0.5, success_radius=1.0)
    return quality_measures(ae, success)


def read_back(db: ImageDatabase, folder):
    overrides = export_database(db, folder)
    composed = compose_database("folder", overrides[1:])
    return load_database(composed.db, data_dir=composed.data_dir, cache_dir=composed.cache_dir)


def test_round_room_round_trip_gives_identical_measures(tmp_path):
    db = round_room()
    back = read_back(db, tmp_path / "export")
    order = [back.index_of(x, y) for x, y in db.positions]
    back = back.subset(order)
    np.testing.assert_array_equal(back.images, db.images)
    direct, folder = measures_of(db), measures_of(back)
    assert np.isfinite(direct.aae) and direct.rr > 0
    assert (folder.aae, folder.mae, folder.rr) == (direct.aae, direct.mae, direct.rr)


def test_synthetic_stand_in_round_trip_gives_identical_measures(tmp_path):
    pytest.importorskip("bionav.db.synthetic")
    composed = compose_database("sim_original", ["db.image_size=[96,14]", f"cache_dir={tmp_path / 'cache'}"])
    db = load_database(composed.db, data_dir=composed.data_dir, cache_dir=composed.cache_dir)
    back = read_back(db, tmp_path / "export")
    back = back.subset([back.index_of(x, y) for x, y in db.positions])
    np.testing.assert_array_equal(back.images, db.images)
    snaps = [0, len(db) // 2]
    direct, folder = measures_of(db, snaps), measures_of(back, snaps)
    assert (folder.aae, folder.mae, folder.rr) == (direct.aae, direct.mae, direct.rr)
