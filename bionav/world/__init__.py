"""Synthetic 3-D worlds and a ray-casting renderer of canonical unfolded panoramas.

* :func:`render_panorama` -- the panorama seen from a pose ``(x, y, z)``,
  heading (radians CCW) in a :class:`Scene`, directly at the requested
  :class:`~bionav.geometry.PanoramaGeometry`; :func:`render_depth` -- the
  distance per pixel.
* :class:`Scene` -- boxes, vertical frusta (cylinders, cones), ellipsoids,
  materials with procedural textures (:mod:`bionav.world.textures`), lights
  (:mod:`bionav.world.lights`) and an optional sky function
  (:mod:`bionav.light.simple_sky`).
* World builders (:mod:`bionav.world.worlds`): the laboratory and its seven
  variants, the hall, the living rooms, the outdoor campus and the apartment
  of the cleaning-robot experiments; each returns a :class:`World` (scene plus
  grid placement) generated from a seed; the five-band garden and backyard of
  the spectral experiments (:mod:`bionav.world.worlds.garden`), shaded under
  spectral daylight by :mod:`bionav.world.spectral_shading`.
"""

from bionav.world.render import RENDERER_VERSION, render_depth, render_panorama
from bionav.world.scene import Scene
from bionav.world.worlds.common import World

__all__ = ["RENDERER_VERSION", "Scene", "World", "render_depth", "render_panorama"]
