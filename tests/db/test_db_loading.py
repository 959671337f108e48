"""load_database dispatch: synthetic source, preprocessing order, config nodes."""

from __future__ import annotations

import sys
import types

import numpy as np
import pytest
from omegaconf import OmegaConf

from bionav.db.config import DatabaseConfig
from bionav.db.database import ImageDatabase
from bionav.db.export import export_database
from bionav.db.loading import load_database
from bionav.errors import UserError
from bionav.geometry import PanoramaGeometry
from bionav.homing.imageops import butterworth_lowpass, resize_images


def test_synthetic_source_calls_the_renderer_lazily(monkeypatch, tmp_path):
    calls = []

    def synthetic_database(name, *, image_size, seed, noise, rotate_current, rotation_seed, cache_dir):
        calls.append(dict(name=name, image_size=image_size, seed=seed, noise=noise,
                          rotate_current=rotate_current, rotation_seed=rotation_seed, cache_dir=cache_dir))
        images = np.full((2, 10, 40), 0.5, np.float32)  # a renderer that ignores image_size
        return ImageDatabase(name, images, [(0, 0), (1, 0)], (2, 1), PanoramaGeometry.square_pixels(40, 10))

    fake = types.ModuleType("bionav.db.synthetic")
    fake.synthetic_database = synthetic_database
    monkeypatch.setitem(sys.modules, "bionav.db.synthetic", fake)
    cfg = OmegaConf.create({"name": "sim_original", "source": "synthetic", "image_size": [20, 5], "seed": 4,
                            "noise": 0.02, "rotate_current": True, "rotation_seed": 9})
    db = load_database(cfg, data_dir=tmp_path, cache_dir=tmp_path / "c")
    assert calls == [dict(name="sim_original", image_size=[20, 5], seed=4, noise=0.02, rotate_current=True,
                          rotation_seed=9, cache_dir=tmp_path / "c")]
    assert db.images.shape == (2, 5, 20) and db.geometry.width == 20


def test_preprocessing_runs_at_native_size_before_the_resize(tmp_path):
    rng = np.random.default_rng(0)
    images = (np.rint(rng.random((3, 12, 48)) * 255) / 255).astype(np.float32)
    src = ImageDatabase("p", images, [(0, 0), (1, 0), (2, 0)], (3, 1), PanoramaGeometry.square_pixels(48, 12))
    export_database(src, tmp_path / "db")
    cfg = DatabaseConfig(name="p", source="folder", path=str(tmp_path / "db"), image_size=[24, 6])
    steps = [{"op": "butterworth", "order": 2, "cutoff": 0.2}]
    db = load_database(cfg, data_dir=tmp_path, cache_dir=tmp_path, preprocess={"name": "x", "steps": steps})
    expected = resize_images(butterworth_lowpass(images, order=2, cutoff=0.2), [24, 6])
    np.testing.assert_allclose(db.images, expected, atol=1e-6)
    assert db.meta["preprocess"] == ["x"]


def test_bad_source_and_size(tmp_path):
    with pytest.raises(UserError, match="db.source"):
        load_database(DatabaseConfig(source="ftp"), data_dir=tmp_path, cache_dir=tmp_path)
    with pytest.raises(UserError, match="image_size"):
        load_database(DatabaseConfig(source="folder", image_size=[0, 3]), data_dir=tmp_path, cache_dir=tmp_path)
    with pytest.raises(UserError, match="db.path=DIR"):
        load_database(DatabaseConfig(name="folder", source="folder"), data_dir=tmp_path, cache_dir=tmp_path)


def test_config_node_with_interpolation_resolves_against_its_root(tmp_path):
    (tmp_path / "hall1").mkdir()
    root = OmegaConf.create({"data_dir": str(tmp_path),
                             "db": {"name": "hall1", "source": "folder", "path": "${data_dir}/hall1"}})
    with pytest.raises(UserError, match=r"no database images found in .*hall1.*it is empty"):
        load_database(root.db, data_dir=tmp_path, cache_dir=tmp_path)
