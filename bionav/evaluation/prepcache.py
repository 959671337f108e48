"""On-disk cache of per-image work, keyed by content hash, safe for concurrent workers.

Per-image results (features, signatures, scale-plane stacks) are stored as
``.npz`` files (never pickles) under
``<cache_dir>/prepared/<method>/<hh>/<hash>.npz``. The key hashes the method's
registry name, its typed config, its ``cache_version``, the image geometry and
the image bytes, so a sweep over methods or parameters recomputes only what
changed. Files are written with :func:`bionav.files.write_atomic`: concurrent workers computing the same entry both write the
same content and never expose a half-written file.

Cacheable results are: an ndarray, a dict of ndarrays, or a dataclass whose
fields are ndarrays (stored with its ``module:qualname`` and rebuilt on load).
Anything else is simply not cached.
"""

from __future__ import annotations

import dataclasses
import importlib
from pathlib import Path
from typing import Any

import numpy as np

from bionav.files import cache_key, write_atomic

_KIND = "__bionav_kind__"
_CLASS = "__bionav_class__"


def _plain(config: Any) -> Any:
    return dataclasses.asdict(config) if dataclasses.is_dataclass(config) and not isinstance(config, type) else config


def prepared_key(
    method_name: str, config: Any, geometry: Any, image: np.ndarray, *, version: str, extra: Any = None
) -> str:
    """The :func:`bionav.files.cache_key` of everything a per-image result depends on.

    ``extra`` holds further configuration the result depends on (e.g. the
    parameter signature's own config for ``homing=parameter``).
    """
    payload = [method_name, version, _plain(config), dataclasses.asdict(geometry), _plain(extra)]
    return cache_key(payload, image)


def _to_arrays(value: Any) -> dict[str, np.ndarray] | None:
    if isinstance(value, np.ndarray):
        return {_KIND: np.array("array"), "value": value}
    if isinstance(value, dict) and value and all(isinstance(k, str) and isinstance(v, np.ndarray) for k, v in value.items()):
        return {_KIND: np.array("dict"), **value}
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        fields = {f.name: getattr(value, f.name) for f in dataclasses.fields(value)}
        if all(isinstance(v, np.ndarray) for v in fields.values()):
            cls = type(value)
            return {_KIND: np.array("dataclass"), _CLASS: np.array(f"{cls.__module__}:{cls.__qualname__}"), **fields}
    return None


def _from_arrays(data: dict[str, np.ndarray]) -> Any:
    kind = str(data.pop(_KIND))
    if kind == "array":
        return data["value"]
    if kind == "dict":
        return data
    module, _, qualname = str(data.pop(_CLASS)).partition(":")
    cls: Any = importlib.import_module(module)
    for part in qualname.split("."):
        cls = getattr(cls, part)
    return cls(**data)


def _extra(method: Any, signature: Any) -> Any:
    """What else the prepared result depends on: the signature's config, the raw horizon radius if set."""
    extra = getattr(signature, "config", None)
    radius = getattr(method, "raw_horizon_radius_px", None)
    if radius is not None and getattr(method.config, "butterworth_relative_to", "panorama") == "raw":
        extra = [_plain(extra), float(radius)]
    return extra


class PreparedCache:
    """Directory of cached per-image results for one method configuration.

    Parameters
    ----------
    root : path-like
        The cache directory (``cfg.cache_dir``).
    method_name : str
        Registry name of the method (``sift``, ``minwarping`` ...).
    """

    def __init__(self, root: str | Path, method_name: str) -> None:
        self.dir = Path(root) / "prepared" / method_name
        self.method_name = method_name
        self.hits = 0
        self.misses = 0

    def _path(self, key: str) -> Path:
        return self.dir / key[:2] / f"{key}.npz"

    def get(self, key: str) -> Any | None:
        path = self._path(key)
        try:
            with np.load(path, allow_pickle=False) as npz:
                data = {k: npz[k] for k in npz.files}
        except (OSError, ValueError, KeyError):
            return None
        try:
            return _from_arrays(data)
        except Exception:
            return None

    def put(self, key: str, value: Any) -> bool:
        arrays = _to_arrays(value)
        if arrays is None:
            return False
        write_atomic(self._path(key), lambda f: np.savez(f, **arrays))
        return True

    def prepare(self, method: Any, image: np.ndarray) -> Any:
        """``method.prepare(image)`` through the cache."""
        signature = getattr(method, "signature", None)
        key = prepared_key(
            self.method_name, method.config, method.geometry, image,
            version=str(getattr(method, "cache_version", "1")),
            extra=_extra(method, signature),
        )
        value = self.get(key)
        if value is not None:
            self.hits += 1
            return value
        self.misses += 1
        value = method.prepare(image)
        self.put(key, value)
        return value
