"""bionav: biologically inspired visual navigation."""

from bionav.files import ensure_numba_cache as _ensure_numba_cache

__version__ = "0.1.0"

_ensure_numba_cache()  # numba can cache the kernels even where the install and the home folder are read-only
