"""bionav.files: the one atomic writer, cache directory and cache key."""

import hashlib
import json
import os
import stat

import numpy as np
import pytest

from bionav.files import cache_key, default_cache_dir, write_atomic, write_json_atomic


def test_write_atomic_text_bytes_and_callback(tmp_path):
    assert write_atomic(tmp_path / "a" / "t.txt", "héllo").read_text(encoding="utf-8") == "héllo"
    assert (tmp_path / "b.bin").exists() is False
    write_atomic(tmp_path / "b.bin", b"\x00\x01")
    assert (tmp_path / "b.bin").read_bytes() == b"\x00\x01"
    write_atomic(tmp_path / "c.npz", lambda f: np.savez(f, x=np.arange(3)))
    with np.load(tmp_path / "c.npz") as npz:
        np.testing.assert_array_equal(npz["x"], [0, 1, 2])
    assert sorted(p.name for p in tmp_path.rglob("*")) == ["a", "b.bin", "c.npz", "t.txt"]


def test_created_files_follow_the_umask(tmp_path):
    old = os.umask(0o022)
    try:
        path = write_atomic(tmp_path / "m.txt", "x")
        other = write_json_atomic(tmp_path / "m.json", {"a": 1})
    finally:
        os.umask(old)
    assert stat.S_IMODE(path.stat().st_mode) == 0o644
    assert stat.S_IMODE(other.stat().st_mode) == 0o644


def test_failed_write_keeps_the_old_file_and_leaves_no_temporary(tmp_path):
    target = tmp_path / "keep.txt"
    write_atomic(target, "old")

    def boom(f):
        f.write(b"half")
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        write_atomic(target, boom)
    assert target.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["keep.txt"]


def test_json_writes_numpy_values(tmp_path):
    path = write_json_atomic(tmp_path / "m.json", {"n": np.int64(3), "x": np.float32(0.5), "v": np.arange(2)})
    assert json.loads(path.read_text()) == {"n": 3, "x": 0.5, "v": [0, 1]}
    assert path.read_text().endswith("\n")


def test_cache_key_is_the_sha256_of_sorted_json_then_arrays():
    params = {"b": 2, "a": [1.5, "x"]}
    expected = hashlib.sha256(b'{"a": [1.5, "x"], "b": 2}').hexdigest()
    assert cache_key(params) == expected
    img = np.arange(6, dtype=np.uint8).reshape(2, 3)
    h = hashlib.sha256(b'{"a": [1.5, "x"], "b": 2}')
    h.update(b"((2, 3), '|u1')")
    h.update(bytes(range(6)))
    assert cache_key(params, img) == h.hexdigest()
    assert cache_key(params, img) != cache_key(params, img.T.copy())
    assert cache_key(params, np.asfortranarray(img)) == cache_key(params, img)


def test_default_cache_dir(monkeypatch, tmp_path):
    monkeypatch.setenv("BIONAV_CACHE", str(tmp_path))
    assert default_cache_dir() == tmp_path
    monkeypatch.delenv("BIONAV_CACHE")
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    assert default_cache_dir() == tmp_path / "home" / ".cache" / "bionav"
