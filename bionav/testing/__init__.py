"""Public assert helpers for plugin authors (use them in your plugin's tests).

Each helper raises ``AssertionError`` with a message that says what was
expected and what was found, so a plugin's test suite reads::

    from bionav.testing import assert_homing_plugin, assert_points_home
    assert_homing_plugin(MyHoming)
    assert_points_home(MyHoming(MyHoming.Config(), geometry=g), snapshot, current, expected_angle=0.7)

Ground truth: :func:`render_pillar_panorama` ray-casts the panorama of a small
textured room with pillars at a known position and heading and returns
``(image, geometry)`` (see docs/plugins.md).
"""

from bionav.testing.homing import (
    assert_homing_plugin,
    assert_points_home,
    assert_recovers_rotation,
    assert_rotation_invariant,
)
from bionav.testing.pillar_scene import DEFAULT_PILLARS, Pillar, render_pillar_panorama

__all__ = [
    "DEFAULT_PILLARS",
    "Pillar",
    "assert_homing_plugin",
    "assert_points_home",
    "assert_recovers_rotation",
    "assert_rotation_invariant",
    "render_pillar_panorama",
]
