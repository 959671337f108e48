"""The per-image cache: round trips, keys, and two workers filling it at once."""

import subprocess
import sys
from dataclasses import dataclass

import numpy as np

from bionav.evaluation.prepcache import PreparedCache
from bionav.evaluation.prepcache import prepared_key as cache_key
from bionav.geometry import PanoramaGeometry
from bionav.homing.features import SiftFeatures


@dataclass
class _Cfg:
    k: int = 3


class _Method:
    """A stand-in method whose prepare counts its calls."""

    def __init__(self, k=3):
        self.config = _Cfg(k)
        self.geometry = PanoramaGeometry.square_pixels(16, 4)
        self.calls = 0

    def prepare(self, image):
        self.calls += 1
        return {"sum": np.array([image.sum() * self.config.k]), "rows": image.mean(axis=1)}


def test_round_trip_of_supported_kinds(tmp_path):
    cache = PreparedCache(tmp_path, "m")
    f = SiftFeatures(np.ones((3, 2), np.float32), np.zeros((3, 128), np.float32), np.zeros(3, np.float32))
    for i, value in enumerate([np.arange(5.0), {"a": np.eye(2)}, f]):
        assert cache.put(f"{i:064x}", value)
        back = cache.get(f"{i:064x}")
        if isinstance(value, SiftFeatures):
            assert isinstance(back, SiftFeatures) and np.array_equal(back.xy, f.xy)
        elif isinstance(value, dict):
            assert np.array_equal(back["a"], np.eye(2))
        else:
            assert np.array_equal(back, value)
    assert not cache.put("f" * 64, [1, 2, 3])  # not cacheable -> not cached


def test_key_depends_on_config_image_and_version(tmp_path):
    g = PanoramaGeometry.square_pixels(16, 4)
    img = np.zeros((4, 16), np.float32)
    base = cache_key("m", _Cfg(3), g, img, version="1")
    assert base == cache_key("m", _Cfg(3), g, img.copy(), version="1")
    img2 = img.copy()
    img2[0, 0] = 1e-3
    assert len({base, cache_key("m", _Cfg(4), g, img, version="1"), cache_key("m", _Cfg(3), g, img2, version="1"),
                cache_key("m", _Cfg(3), g, img, version="2"), cache_key("n", _Cfg(3), g, img, version="1")}) == 5


def test_second_sweep_job_reuses_per_image_work(tmp_path):
    images = np.random.default_rng(0).random((6, 4, 16)).astype(np.float32)
    m1, m2 = _Method(), _Method()
    first = [PreparedCache(tmp_path, "m").prepare(m1, im) for im in images]
    cache = PreparedCache(tmp_path, "m")
    second = [cache.prepare(m2, im) for im in images]
    assert m1.calls == 6 and m2.calls == 0 and cache.hits == 6
    for a, b in zip(first, second):
        assert np.array_equal(a["rows"], b["rows"])


WORKER = """
import sys, numpy as np
from bionav.evaluation.prepcache import PreparedCache
from bionav.geometry import PanoramaGeometry
class Cfg:
    pass
class M:
    def __init__(self):
        self.config = {"k": 1}
        self.geometry = PanoramaGeometry.square_pixels(64, 8)
    def prepare(self, image):
        return {"x": np.repeat(image, 50, axis=0)}
images = np.random.default_rng(1).random((40, 8, 64)).astype(np.float32)
cache = PreparedCache(sys.argv[1], "m")
for _ in range(3):
    for im in images:
        cache.prepare(M(), im)
"""


def test_two_workers_fill_the_cache_at_once(tmp_path):
    procs = [subprocess.Popen([sys.executable, "-c", WORKER, str(tmp_path)]) for _ in range(2)]
    assert [p.wait(timeout=120) for p in procs] == [0, 0]
    files = list((tmp_path / "prepared" / "m").rglob("*.npz"))
    assert len(files) == 40
    assert not list((tmp_path / "prepared" / "m").rglob(".tmp-*"))
    images = np.random.default_rng(1).random((40, 8, 64)).astype(np.float32)
    cache = PreparedCache(tmp_path, "m")

    class M:
        config = {"k": 1}
        geometry = PanoramaGeometry.square_pixels(64, 8)

        def prepare(self, image):
            raise AssertionError("should be cached")

    for im in images:
        assert np.array_equal(cache.prepare(M(), im)["x"], np.repeat(im, 50, axis=0))
