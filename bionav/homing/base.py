"""The contract between homing methods and the experiments that evaluate them."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, ClassVar, Mapping

import numpy as np

from bionav.geometry import PanoramaGeometry


@dataclass(frozen=True)
class HomeVector:
    """Result of one homing computation.

    Attributes
    ----------
    angle : float
        Home direction in radians, counter-clockwise, in the *current view's own
        frame* (0 = the direction of the current panorama's column 0). NaN when
        the method could not decide (see ``valid``).
    compass : float or None
        Estimated rotation of the current view relative to the snapshot,
        ``heading(current) - heading(snapshot)`` in radians CCW, for methods that
        estimate it (the warping family's psi); ``None`` otherwise.
    extras : dict
        Method-specific diagnostics (number of matches, best score, ...);
        JSON-serialisable scalars only.
    """

    angle: float
    compass: float | None = None
    extras: Mapping[str, Any] = field(default_factory=dict)

    @property
    def valid(self) -> bool:
        """False when the method gave no direction (e.g. no feature matches)."""
        return bool(np.isfinite(self.angle))


class HomingMethod:
    """Base class of every ``bionav.homing`` plugin.

    A plugin subclasses this, sets ``Config`` to a dataclass of its parameters
    (this dataclass is what Hydra validates: ``homing.<field>=<value>``), and
    implements :meth:`home_vector`. Per-image work goes into :meth:`prepare`,
    which the grid runner calls exactly once per image; :meth:`home_vector`
    receives the prepared objects.

    Class attributes
    ----------------
    Config : type
        Dataclass of the method's parameters.
    requires_alignment : bool
        True when the method assumes snapshot and current view share one
        orientation (no compass of its own).
    uses_test_steps : bool
        True when :meth:`home_vector` needs the prepared images of the current
        position's grid neighbours (passed as ``neighbours``).
    """

    Config: ClassVar[type]
    requires_alignment: ClassVar[bool] = True
    uses_test_steps: ClassVar[bool] = False

    def __init__(self, config: Any, *, geometry: PanoramaGeometry) -> None:
        from bionav.validation import checked_config

        # the Python API's check; a config from the command line (typed_config) was checked there, not again
        self.config = checked_config(config, prefix="homing")
        self.geometry = geometry

    def prepare(self, image: np.ndarray) -> Any:
        """Per-image work (features, filtered stacks, signatures).

        Parameters
        ----------
        image : ndarray, shape (H, W), float32 in [0, 1]
            Canonical panorama (see :mod:`bionav.geometry`).

        Returns
        -------
        object
            Anything :meth:`home_vector` accepts; an ndarray or a dict of
            ndarrays, so it can be cached on disk. The default returns the image.
        """
        return image

    def describe_prepared(self, prepared: Any) -> Mapping[str, float]:
        """Numbers describing one prepared image (e.g. ``{"keypoints": 413.0}``).

        Experiments average them over a database's images and report them as
        ``<name>_per_image`` metrics. The default describes nothing.
        """
        return {}

    def home_vector(
        self,
        snapshot: Any,
        current: Any,
        *,
        neighbours: Mapping[tuple[int, int], Any] | None = None,
    ) -> HomeVector:
        """Home vector from the current view towards the snapshot position.

        Parameters
        ----------
        snapshot, current : object
            Results of :meth:`prepare` for the snapshot and the current view.
        neighbours : mapping, optional
            Only for ``uses_test_steps`` methods: prepared images of the current
            position's neighbours keyed by grid offset ``(dx, dy)`` in the
            current view's frame; missing neighbours are absent.

        Returns
        -------
        HomeVector
        """
        raise NotImplementedError

    def all_pairs_angles(self, prepared, *, headings: np.ndarray, neighbours: np.ndarray) -> np.ndarray | None:
        """Optional batch path: home angles of every pair of one database at once.

        The all-pairs runner (:func:`bionav.evaluation.pairs.home_vector_matrix`)
        uses it when snapshots and current views come from one database; it
        must give the same angles as :meth:`home_vector` pair by pair.

        Parameters
        ----------
        prepared : sequence
            :meth:`prepare` of every image of the database, length ``N``.
        headings : ndarray, shape (N,)
            Heading of every view in the grid frame (radians CCW).
        neighbours : ndarray of int, shape (N, 4)
            Index of each cell's grid neighbours at offsets ``(+1, 0), (-1, 0),
            (0, +1), (0, -1)`` (-1 where missing), see
            :func:`bionav.evaluation.pairs.neighbour_table`.

        A method may also accept the keywords ``snapshot_index`` (sequence of
        int: only these rows are needed), ``workers`` (int: threads it may use)
        ``progress`` (a ``progress(iterable, desc=..., total=...)``
        wrapper) and ``on_row`` (the runner's ``on_row(s, angles, compass)``,
        to be called in the caller's thread as soon as snapshot row ``s`` is
        complete; then the runner does not call it); the runner passes those
        its signature names.

        Returns
        -------
        ndarray, shape (N, N), or None
            ``[s, c]``: home direction from current view ``c`` to snapshot ``s``
            in the *grid frame* (radians CCW; NaN where the method gives none);
            ``None`` (the default) when the method has no batch path.
        """
        return None
