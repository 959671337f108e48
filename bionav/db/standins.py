"""The table of the synthetic stand-ins (thesis table 3.1): name, grid, spacing, mirror and world builder of each.

:data:`SYNTHETIC_DATABASES` is read by the ``db`` config (a stand-in's own grid, spacing and horizon,
:meth:`bionav.db.config.DatabaseConfig.own_values`) and by the renderer of the stand-ins
(:func:`bionav.db.synthetic.synthetic_database`); the worlds are built only when a database is
rendered (``builder(seed)``). Sizes ``(W, H)`` in pixels, spacings in metres.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

from bionav.errors import UserError
from bionav.geometry import PanoramaGeometry

#: Native size ``(W, H)`` of the stand-ins (the user may ask for any other size).
NATIVE_SIZE = (561, 81)

def ultra_wide_geometry(width: int = NATIVE_SIZE[0], height: int = NATIVE_SIZE[1]) -> PanoramaGeometry:
    """Ultra-wide-view mirror: square pixels, horizon on the middle row (about +-26 deg at 561 x 81)."""
    return PanoramaGeometry.square_pixels(*NATIVE_SIZE).resized(width, height)


def normal_view_geometry(width: int = NATIVE_SIZE[0], height: int = NATIVE_SIZE[1]) -> PanoramaGeometry:
    """Normal-view mirror: narrower view upwards (about +17 deg) and more of the ground (about -34 deg)."""
    native = PanoramaGeometry.square_pixels(*NATIVE_SIZE, horizon_row=27.0)
    return native.resized(width, height)


def _lab(variant: str):
    def build(seed: int):
        from bionav.world.worlds.lab import build_lab_variant

        return build_lab_variant(variant, seed)

    return build


def _lazy(module: str, func: str, **kwargs):
    def build(seed: int):
        import importlib

        return getattr(importlib.import_module(module), func)(seed, **kwargs)

    return build


@dataclass(frozen=True)
class SyntheticSpec:
    """One synthetic stand-in of thesis table 3.1.

    Attributes
    ----------
    name : str
        ``sim_<thesis name>``.
    grid_shape : (int, int)
        ``(nx, ny)`` of the declared grid.
    spacing_m : float
        Grid spacing in metres.
    n_images : int
        Number of existing cells (table 3.1).
    mirror : str
        ``ultra-wide`` or ``normal-view``.
    description : str
        What the world shows.
    builder : callable
        ``builder(seed) -> World``.
    geometry : callable
        ``geometry(W, H) -> PanoramaGeometry``.
    native_size : (int, int)
        Native ``(W, H)``.
    positions_from : str
        How the real database's positions were recorded (thesis 3.1): ``odometry``,
        ``semi-automatic`` or ``outdoor-odometry``; selects the pose errors of
        ``realism="camera"`` (:data:`bionav.db.camera.POSE_ERRORS`).
    """

    name: str
    grid_shape: tuple[int, int]
    spacing_m: float
    n_images: int
    mirror: str
    description: str
    builder: Callable
    geometry: Callable[[int, int], PanoramaGeometry] = ultra_wide_geometry
    native_size: tuple[int, int] = NATIVE_SIZE
    positions_from: str = "odometry"


def _spec(name, grid, spacing, n, mirror, description, builder, positions_from="odometry") -> SyntheticSpec:
    geom = normal_view_geometry if mirror == "normal-view" else ultra_wide_geometry
    return SyntheticSpec(name, grid, spacing, n, mirror, description, builder, geom, NATIVE_SIZE, positions_from)


#: The 13 synthetic stand-ins, by name.
SYNTHETIC_DATABASES: dict[str, SyntheticSpec] = {
    s.name: s
    for s in [
        _spec("sim_original", (10, 17), 0.3, 170, "ultra-wide",
              "laboratory, curtains and door closed, both ceiling light bands on", _lab("original")),
        _spec("sim_arboreal", (10, 17), 0.3, 170, "ultra-wide",
              "the laboratory with an arboreal plant in the middle", _lab("arboreal")),
        _spec("sim_chairs", (10, 17), 0.3, 170, "ultra-wide", "the laboratory with chairs added", _lab("chairs")),
        _spec("sim_day", (10, 17), 0.3, 170, "ultra-wide",
              "the laboratory with open curtains and daylight", _lab("day")),
        _spec("sim_doorlit", (10, 17), 0.3, 170, "ultra-wide",
              "the laboratory with only the door-side light band on", _lab("doorlit")),
        _spec("sim_screen", (10, 17), 0.3, 170, "ultra-wide",
              "the laboratory with a white projection screen", _lab("screen")),
        _spec("sim_twilight", (10, 17), 0.3, 170, "ultra-wide",
              "the laboratory with open curtains at twilight", _lab("twilight")),
        _spec("sim_winlit", (10, 17), 0.3, 170, "ultra-wide",
              "the laboratory with only the window-side light band on", _lab("winlit")),
        _spec("sim_hall1", (10, 20), 0.5, 170, "ultra-wide",
              "a large, dim, achromatic hall at night (cells missing under a kiosk)",
              _lazy("bionav.world.worlds.hall", "build_hall", part=1)),
        _spec("sim_hall2", (10, 20), 0.5, 170, "ultra-wide", "another part of the hall",
              _lazy("bionav.world.worlds.hall", "build_hall", part=2)),
        _spec("sim_moeller1", (11, 22), 0.1, 242, "ultra-wide", "a living room",
              _lazy("bionav.world.worlds.living", "build_living_room"), "semi-automatic"),
        _spec("sim_roeben1", (11, 36), 0.1, 396, "ultra-wide",
              "a living room with kitchen, furniture close to the grid",
              _lazy("bionav.world.worlds.living", "build_living_kitchen"), "semi-automatic"),
        _spec("sim_uni", (10, 17), 1.0, 170, "normal-view",
              "outdoors at a university entrance: buildings, trees, sky and sun",
              _lazy("bionav.world.worlds.outdoor", "build_uni"), "outdoor-odometry"),
    ]
}


def synthetic_database_names() -> list[str]:
    """Names of the synthetic stand-ins."""
    return sorted(SYNTHETIC_DATABASES)


def get_spec(name: str) -> SyntheticSpec:
    """The :class:`SyntheticSpec` of a stand-in; raises :class:`UserError` for unknown names."""
    if name not in SYNTHETIC_DATABASES:
        raise UserError(
            f"Unknown synthetic database {name!r}. Available synthetic databases: "
            f"{', '.join(synthetic_database_names())}. Choose one of them with db=<name>."
        )
    return SYNTHETIC_DATABASES[name]
