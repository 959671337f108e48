"""Public assert helpers for plugin authors (use them in your plugin's tests).

Each helper raises ``AssertionError`` with a message that says what was
expected and what was found, so a plugin's test suite reads::

    from bionav.testing import assert_homing_plugin, assert_points_home
    assert_homing_plugin(MyHoming)
    assert_points_home(MyHoming(MyHoming.Config(), geometry=g), snapshot, current, expected_angle=0.7)
"""

from bionav.testing.homing import (
    assert_homing_plugin,
    assert_points_home,
    assert_recovers_rotation,
    assert_rotation_invariant,
)

__all__ = ["assert_homing_plugin", "assert_points_home", "assert_recovers_rotation", "assert_rotation_invariant"]
