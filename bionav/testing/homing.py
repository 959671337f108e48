"""Assert helpers for homing-method and signature plugins."""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from bionav.geometry import angular_difference
from bionav.homing.base import HomeVector, HomingMethod


def _fail(message: str) -> None:
    raise AssertionError(message)


def assert_homing_plugin(cls: type) -> None:
    """Check the static contract of a ``bionav.homing`` plugin class.

    A ``HomingMethod`` subclass with a ``Config`` dataclass whose every field
    has a default (so ``homing=<name>`` works with no YAML), and boolean
    ``requires_alignment`` / ``uses_test_steps``.
    """
    if not (isinstance(cls, type) and issubclass(cls, HomingMethod)):
        _fail(f"{cls!r} is not a subclass of bionav.homing.HomingMethod")
    config = getattr(cls, "Config", None)
    if config is None or not dataclasses.is_dataclass(config):
        _fail(f"{cls.__name__}.Config must be a dataclass of the method's parameters")
    missing = [f.name for f in dataclasses.fields(config)
               if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING]
    if missing:
        _fail(f"{cls.__name__}.Config fields without defaults: {', '.join(missing)}")
    if "name" in {f.name for f in dataclasses.fields(config)}:
        _fail(f"{cls.__name__}.Config must not have a field 'name' (bionav adds the registry name)")
    for attr in ("requires_alignment", "uses_test_steps"):
        if not isinstance(getattr(cls, attr), bool):
            _fail(f"{cls.__name__}.{attr} must be a bool")


def _home_vector(method: HomingMethod, snapshot: np.ndarray, current: np.ndarray) -> HomeVector:
    hv = method.home_vector(method.prepare(snapshot), method.prepare(current))
    if not isinstance(hv, HomeVector):
        _fail(f"home_vector must return a bionav.homing.HomeVector, got {type(hv).__name__}")
    return hv


def assert_points_home(
    method: HomingMethod,
    snapshot: np.ndarray,
    current: np.ndarray,
    *,
    expected_angle: float,
    tolerance: float = np.pi / 4,
) -> HomeVector:
    """The method's home vector from ``current`` to ``snapshot`` is within ``tolerance`` of ``expected_angle``.

    Parameters
    ----------
    method : HomingMethod
        An instantiated method.
    snapshot, current : ndarray, shape (H, W)
        Canonical panoramas (e.g. rendered at known positions).
    expected_angle : float
        True home direction in the current view's frame, radians CCW.
    tolerance : float
        Largest accepted angular error, radians.

    Returns
    -------
    HomeVector
        The result, for further checks.
    """
    hv = _home_vector(method, snapshot, current)
    if not hv.valid:
        _fail(f"{type(method).__name__} gave no home direction (angle NaN)")
    err = float(angular_difference(hv.angle, expected_angle))
    if err > tolerance:
        _fail(
            f"{type(method).__name__} points {np.rad2deg(hv.angle):.1f} deg, expected "
            f"{np.rad2deg(expected_angle):.1f} deg (error {np.rad2deg(err):.1f} > {np.rad2deg(tolerance):.1f} deg)"
        )
    return hv


def assert_recovers_rotation(
    method: HomingMethod,
    snapshot: np.ndarray,
    *,
    shift_columns: int,
    current: np.ndarray | None = None,
    tolerance: float = np.deg2rad(5.0),
) -> HomeVector:
    """A method with a visual compass recovers the rotation of a column-rolled current view.

    The current view (the snapshot itself unless given) is rolled by
    ``shift_columns`` with ``np.roll(image, -shift_columns, axis=1)``, which
    is a robot turned counter-clockwise by ``2*pi*shift_columns/W``; the
    method's ``compass`` must equal that angle within ``tolerance``.
    """
    base = snapshot if current is None else current
    width = base.shape[1]
    rolled = np.roll(base, -shift_columns, axis=1)
    hv = _home_vector(method, snapshot, rolled)
    if hv.compass is None:
        _fail(f"{type(method).__name__} returns no compass estimate (HomeVector.compass is None)")
    expected = 2 * np.pi * shift_columns / width
    err = float(angular_difference(hv.compass, expected))
    if err > tolerance:
        _fail(
            f"{type(method).__name__} estimates a rotation of {np.rad2deg(hv.compass):.1f} deg, expected "
            f"{np.rad2deg(expected):.1f} deg (error {np.rad2deg(err):.1f} deg)"
        )
    return hv


def assert_rotation_invariant(signature: Any, image: np.ndarray, *, shifts=(1, 7, 33), rtol: float = 1e-6) -> None:
    """A signature that claims rotation invariance gives the same vector for column-rolled images."""
    if not getattr(signature, "rotation_invariant", False):
        _fail(f"{type(signature).__name__} does not claim rotation invariance")
    reference = np.asarray(signature.compute(image), dtype=float)
    for shift in shifts:
        got = np.asarray(signature.compute(np.roll(image, shift, axis=1)), dtype=float)
        if not np.allclose(got, reference, rtol=rtol, atol=rtol * max(1.0, float(np.max(np.abs(reference))))):
            _fail(f"{type(signature).__name__} changes under a roll by {shift} columns")
