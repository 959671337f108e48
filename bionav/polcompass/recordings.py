"""Recordings of a real POL-OP compass: JSON files, sessions, hardware faults.

Format (Gkanias et al. 2023, doi:10.1038/s44172-023-00132-w; one file per
full rotation of the robot): a JSON object with ``pol_op_0`` ..
``pol_op_{K-1}``, each a list of ``N`` samples of ``P`` photodiode counts,
``azimuths`` (the ``K`` unit azimuths, radians, clockwise from the robot's
front) and ``yaw`` (``N`` IMU yaw angles, radians, counter-clockwise, up to a
constant). A *session* is a folder of such files named ``<n>.json``, in a
folder named ``<HH-MM>__<Day>_<dd-mm-yy>`` (local time); a folder named
``canopy_data`` on its path marks sessions under tree canopy, ``tod_data``
time-of-day sessions (:func:`path_condition`).

Faults are data: :func:`sample_validity` marks, per sample and unit,
saturated, overflowing or dark counts and photodiode pairs whose total light
disagrees (a bad photodiode at that moment); :func:`detect_faults` summarises
a session per unit and names units to drop (``exclude_units=auto``):
polarization-blind units (orthogonal photodiodes reading identical counts),
units with a bad photodiode (the two POL-OPs' total light differs by more
than ``imbalance_decades`` in the median) and units that are unusable most of
the time.
"""

from __future__ import annotations

import datetime as _dt
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from bionav.errors import UserError

ROTATION_FILE = re.compile(r"^(\d+)\.json$")
SESSION_DIR = re.compile(r"^(\d{1,2})-(\d{2})__\w*?_?(\d{2})-(\d{2})-(\d{2})$")
#: a path part naming a condition (:func:`path_condition`): the word ``canopy`` or ``tod`` at its start
CONDITION_WORD = re.compile(r"^(canopy|tod)(?![a-z])")


class RecordingError(UserError):
    """A recording file that is not what its name says (names the file and the field)."""


@dataclass(frozen=True)
class Rotation:
    """One recorded rotation.

    Attributes
    ----------
    path : Path
    counts : ndarray, shape ``(N, K, P)``
        Photodiode counts in file order.
    yaw : ndarray, shape ``(N,)``
        IMU yaw, radians CCW.
    file_azimuths : ndarray, shape ``(K,)``
        Unit azimuths as stored (radians, clockwise from the front).
    """

    path: Path
    counts: np.ndarray
    yaw: np.ndarray
    file_azimuths: np.ndarray


@dataclass
class Session:
    """A folder of rotations recorded under one sky.

    Attributes
    ----------
    name : str
        Folder path relative to the recordings root.
    condition : str
        ``tod``, ``canopy`` or ``unknown`` (:func:`path_condition`).
    local_time : datetime or None
        Start time, naive local time from the folder name.
    rotations : list of Rotation
    """

    name: str
    condition: str
    local_time: _dt.datetime | None
    rotations: list = field(default_factory=list)

    @property
    def day(self) -> str:
        return self.local_time.strftime("%Y-%m-%d") if self.local_time else ""

    @property
    def time_of_day(self) -> str:
        return self.local_time.strftime("%H:%M") if self.local_time else ""

    def time_utc(self, utc_offset_hours: float) -> _dt.datetime | None:
        """Start time in UTC for a site ``utc_offset_hours`` ahead of UTC."""
        if self.local_time is None:
            return None
        tz = _dt.timezone(_dt.timedelta(hours=float(utc_offset_hours)))
        return self.local_time.replace(tzinfo=tz).astimezone(_dt.timezone.utc)


#: larger rotation files are refused before they are read (bytes; a real one is well below 1 MB)
MAX_RECORDING_BYTES = 64 * 2**20


def _fail(path, field_name, problem):
    raise RecordingError(
        f"The recording {path} is not a POL-OP rotation file: field {field_name!r} {problem}. Each file needs "
        "pol_op_0..pol_op_<K-1> (per sample the photodiode counts of that unit, non-negative numbers), azimuths "
        "(one per unit, radians) and yaw (one per sample, radians); fix or remove the file."
    )


def load_rotation(path, *, n_photodiodes: int = 4) -> Rotation:
    """Read and validate one rotation file.

    Raises
    ------
    RecordingError
        Naming the file and the field: another layout, a missing unit, NaN or
        negative counts, a yaw series of another length.
    """
    from bionav.files import read_json_file, user_path

    path = user_path(path)
    try:
        data = read_json_file(path, what="The recording", fix="Re-export the file as UTF-8 JSON or remove it.",
                              max_bytes=MAX_RECORDING_BYTES)
    except UserError as exc:
        raise RecordingError(str(exc)) from None
    if not isinstance(data, dict):
        _fail(path, "<top level>", f"is a JSON {type(data).__name__}, not an object")
    # unit numbers as strings first: `pol_op_99999999999` must not build a range of 10^11 units
    units = sorted(int(k[len("pol_op_"):]) for k in data if re.fullmatch(r"pol_op_\d{1,6}", k))
    odd = sorted(k for k in data if k.startswith("pol_op_") and not re.fullmatch(r"pol_op_\d{1,6}", k))
    if odd:
        _fail(path, odd[0], "is not a unit key pol_op_<n> with n below 1000000")
    if not units:
        _fail(path, "pol_op_0", f"is missing (keys present: {', '.join(sorted(data)[:8])})")
    missing = next((i for i, u in enumerate(units) if u != i), None)
    if missing is not None:
        _fail(path, f"pol_op_{missing}", "is missing (unit numbers must run from 0 without gaps)")
    for key in ("azimuths", "yaw"):
        if key not in data:
            _fail(path, key, "is missing")
    k = len(units)
    try:
        azimuths = np.asarray(data["azimuths"], float)
    except (TypeError, ValueError, OverflowError):
        _fail(path, "azimuths", "is not a list of numbers")
    if azimuths.shape != (k,) or not np.all(np.isfinite(azimuths)):
        _fail(path, "azimuths", f"must hold {k} finite numbers (one per unit), got shape {azimuths.shape}")
    try:
        yaw = np.asarray(data["yaw"], float)
    except (TypeError, ValueError, OverflowError):
        _fail(path, "yaw", "is not a list of numbers")
    if yaw.ndim != 1 or not np.all(np.isfinite(yaw)):
        _fail(path, "yaw", "must be a flat list of finite numbers")
    counts = []
    for u in range(k):
        key = f"pol_op_{u}"
        try:
            c = np.asarray(data[key], float)
        except (TypeError, ValueError, OverflowError):
            _fail(path, key, "is not a list of count lists")
        if c.ndim != 2 or c.shape[1] != n_photodiodes:
            _fail(path, key, f"must be N x {n_photodiodes} counts, got shape {c.shape}")
        if c.shape[0] != yaw.size:
            _fail(path, "yaw", f"has {yaw.size} samples but {key} has {c.shape[0]}")
        if not np.all(np.isfinite(c)):
            _fail(path, key, f"holds NaN or infinite counts (first at sample {int(np.argwhere(~np.isfinite(c))[0, 0])})")
        if np.any(c < 0):
            _fail(path, key, f"holds negative counts (first at sample {int(np.argwhere(c < 0)[0, 0])})")
        counts.append(c)
    return Rotation(path, np.stack(counts, axis=1), yaw, azimuths)


def parse_session_time(folder: str) -> _dt.datetime | None:
    """Local start time from a folder name ``HH-MM__<Day>_dd-mm-yy`` (None if it does not match)."""
    m = SESSION_DIR.match(folder)
    if not m:
        return None
    hh, mm, dd, mo, yy = (int(v) for v in m.groups())
    try:
        return _dt.datetime(2000 + yy, mo, dd, hh, mm)
    except ValueError:
        return None


def path_condition(folder) -> str:
    """The condition a session folder's path names: ``canopy``, ``tod`` or ``unknown``.

    The folder's own name and every folder above it count, the nearest first: a part that is or starts
    with the word ``canopy`` (``canopy_data``, ``Canopy-2022``; not ``canopyx``) marks sessions under tree
    canopy, one with the word ``tod`` (``tod_data``; not ``today``) time-of-day sessions under open sky,
    whichever is nearer the session. So
    ``recordings.path`` may point at the whole recordings, a condition's folder, a day's folder or one
    session. A path naming neither is ``unknown``: such a session is scored and reported under that
    name and never self-calibrates (docs/polcompass.md).
    """
    from bionav.files import user_path

    for part in reversed(user_path(folder).resolve().parts):
        marker = CONDITION_WORD.match(part.lower())
        if marker:
            return marker.group(1)
    return "unknown"


def find_sessions(root) -> list[tuple[Path, list[Path]]]:
    """Session folders below ``root`` (or ``root`` itself): ``(folder, rotation files sorted by number)``."""
    from bionav.files import not_a_regular_file, user_path

    root = user_path(root)
    problem = not_a_regular_file(root)
    if problem is None:
        return [(root.parent, [root])]
    if problem != "does not exist" and not root.is_dir():
        raise UserError(
            f"recordings.path={root} {problem}. Point it at a folder of POL-OP recordings (e.g. "
            "../shared/data/celestial-compass, or one session folder holding 1.json, 2.json, ...)."
        )
    if not root.is_dir():
        raise UserError(
            f"recordings.path={root} does not exist. Point it at a folder of POL-OP recordings (e.g. "
            "../shared/data/celestial-compass, or one session folder holding 1.json, 2.json, ...)."
        )
    out = []
    for folder in sorted({p.parent for p in root.rglob("*.json") if ROTATION_FILE.match(p.name)}):
        files = sorted((p for p in folder.iterdir() if ROTATION_FILE.match(p.name)), key=lambda p: int(p.stem))
        out.append((folder, files))
    if not out:
        raise UserError(
            f"recordings.path={root} holds no rotation files (<n>.json); point it at a folder of POL-OP "
            "recordings such as ../shared/data/celestial-compass."
        )
    return out


def load_sessions(root, *, n_photodiodes: int = 4):
    """Load every session below ``root``; bad files are collected, not fatal.

    Returns
    -------
    sessions : list of Session
        Sessions with at least one good file.
    errors : list of (Path, str)
        Each bad file with its message.
    """
    from bionav.files import user_path

    root = user_path(root)
    sessions, errors = [], []
    for folder, files in find_sessions(root):
        rel = folder.relative_to(root) if folder != root and root.is_dir() else Path(folder.name)
        session = Session(str(rel), path_condition(folder), parse_session_time(folder.name))
        for f in files:
            try:
                session.rotations.append(load_rotation(f, n_photodiodes=n_photodiodes))
            except RecordingError as exc:
                errors.append((f, str(exc)))
        if session.rotations:
            k = {r.counts.shape[1] for r in session.rotations}
            if len(k) > 1:
                errors.append((folder, f"The session {folder} mixes files with different unit counts {sorted(k)}; one session "
                                       "holds one sensor layout: move the files of the other layout to their own folder."))
                continue
            sessions.append(session)
    return sessions, errors


#: a rotation file whose logged yaw starts at rest (first samples within ``YAW_REST_DEG``) within
#: ``YAW_ZERO_DEG`` of zero starts a new run of the yaw's reference (:func:`yaw_restarts`)
YAW_ZERO_DEG = 0.3
YAW_REST_DEG = 0.1
YAW_REST_SAMPLES = 5


def yaw_restarts(yaws, *, zero_deg: float = YAW_ZERO_DEG, rest_deg: float = YAW_REST_DEG,
                 rest_samples: int = YAW_REST_SAMPLES) -> np.ndarray:
    """Which rotations start a new run of the logged yaw's reference, shape ``(R,)`` bool.

    The recorded robot's yaw (Gkanias et al. 2023) is an integrated IMU angle
    known only up to a constant, and that constant holds only while the
    IMU keeps integrating. Between rotation files the robot either turns back
    to its yaw zero (the next file starts where the controller stopped, a few
    tenths of a degree off zero, and the reference is unchanged) or the
    odometry restarts: the next file then starts *at rest at exactly zero*,
    wherever the robot points, and the reference moves by an unlogged angle.
    A file whose first ``rest_samples`` yaw samples span less than
    ``rest_deg`` and whose first sample lies within ``zero_deg`` of zero is
    taken as such a restart. On the sessions in ``../shared/data`` the
    decoded heading's per-rotation offset steps by a median of 3.5 degrees
    where this marks a restart and by 0.7 degrees elsewhere (docs/polcompass.md,
    "The reference: the logged yaw restarts").

    Parameters
    ----------
    yaws : sequence of ndarray
        Each rotation's logged yaw (radians), in recording order.
    zero_deg, rest_deg : float
        Degrees, see above.
    rest_samples : int
        Samples at the start of a file that must be at rest.

    Returns
    -------
    ndarray of bool, shape ``(R,)``
        True where a rotation starts a new run; the first rotation always does.
    """
    out = np.zeros(len(yaws), bool)
    for i, yaw in enumerate(yaws):
        head = np.degrees(np.unwrap(np.asarray(yaw, float)[:rest_samples]))
        start = (head[0] + 180.0) % 360.0 - 180.0 if head.size else np.inf
        out[i] = i == 0 or (abs(start) <= zero_deg and float(np.ptp(head)) <= rest_deg)
    return out


def pair_imbalance(counts):
    """``log10`` of the total light through the first vs the second POL-OP of each unit.

    Both pairs of orthogonal polarizers see the whole intensity, so this is 0
    for a healthy unit (up to photodiode gains). Shape ``(..., K)``; needs
    four photodiodes per unit in the order of :meth:`PolArray.fan8`.
    """
    c = np.asarray(counts, float)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.log10((c[..., 0] + c[..., 1]) / (c[..., 2] + c[..., 3]))


def photodiode_validity(counts, *, saturation_counts: float, dark_counts: float):
    """Which photodiodes read usable counts, shape ``(N, K, P)``: below ``saturation_counts`` (not saturated
    or overflowing) and at least ``dark_counts`` (a zero has no log ratio; a lone zero among lit
    photodiodes is a read fault of that photodiode)."""
    c = np.asarray(counts, float)
    return (c < saturation_counts) & (c >= dark_counts)


def pol_op_validity(counts, pairs, *, saturation_counts: float, dark_counts: float):
    """Which POL-OPs read usable counts: both photodiodes of the pair usable (:func:`photodiode_validity`).

    Parameters
    ----------
    counts : ndarray, shape ``(N, K, P)``
    pairs : ndarray of int, shape ``(J, 2)``
        Photodiode indices of each POL-OP (:attr:`bionav.polcompass.array.PolArray.pairs`).

    Returns
    -------
    ndarray of bool, shape ``(N, K, J)``
        A unit with one saturated pair still has its other POL-OP, one equation
        ``x = d cos(2a - 2 alpha)`` (:func:`bionav.polcompass.decoders.sun_from_pol_op_fit`).
    """
    ok = photodiode_validity(counts, saturation_counts=saturation_counts, dark_counts=dark_counts)
    pairs = np.atleast_2d(np.asarray(pairs, int))
    return ok[..., pairs[:, 0]] & ok[..., pairs[:, 1]]


def sample_validity(counts, *, saturation_counts: float, dark_counts: float, imbalance_decades: float):
    """Which units give usable readings at each sample, shape ``(N, K)``.

    A unit is unusable at a sample when any photodiode reads at or above
    ``saturation_counts`` (saturated or overflowing), below ``dark_counts``,
    or (four photodiodes) when its two POL-OPs' total light differs by more
    than ``imbalance_decades``.
    """
    c = np.asarray(counts, float)
    ok = np.all(photodiode_validity(c, saturation_counts=saturation_counts, dark_counts=dark_counts), axis=-1)
    if c.shape[-1] == 4:
        imb = pair_imbalance(c)
        ok &= np.isfinite(imb) & (np.abs(imb) <= imbalance_decades)
    return ok


@dataclass(frozen=True)
class UnitFault:
    """Fault summary of one unit over a session."""

    unit: int
    saturated_fraction: float
    dark_fraction: float
    blind_fraction: float
    imbalance_decades: float
    usable_fraction: float
    excluded: bool
    reason: str

    def to_dict(self) -> dict:
        return {k: (None if isinstance(v, float) and not np.isfinite(v) else v) for k, v in self.__dict__.items()}


def detect_faults(
    counts,
    *,
    saturation_counts: float,
    dark_counts: float,
    imbalance_decades: float = 0.15,
    blind_fraction: float = 0.5,
    min_usable_fraction: float = 0.05,
    pairs=None,
) -> list[UnitFault]:
    """Per-unit fault report of a session from its counts alone.

    Parameters
    ----------
    counts : ndarray, shape ``(N, K, P)``
        All samples of the session.
    saturation_counts, dark_counts : float
        Per-sample limits (see :func:`sample_validity`).
    imbalance_decades : float
        Median POL-OP light imbalance beyond which a photodiode is bad.
    blind_fraction : float
        Fraction of lit samples with identical orthogonal photodiodes beyond
        which a unit is polarization-blind.
    min_usable_fraction : float
        Units usable at fewer samples are dropped too.
    pairs : ndarray of int, shape ``(J, 2)``, optional
        The POL-OPs' photodiode pairs: a unit counts as usable at a sample where one of its POL-OPs is
        (:func:`pol_op_validity`; a unit whose one pair is always saturated still gives the other). None:
        only where every photodiode is usable.

    Returns
    -------
    list of UnitFault
    """
    c = np.asarray(counts, float)
    n, k, p = c.shape
    sat = (c.max(axis=-1) >= saturation_counts).mean(axis=0)
    lit = c.min(axis=-1) >= dark_counts
    dark = 1.0 - lit.mean(axis=0)
    if pairs is None:
        usable = sample_validity(c, saturation_counts=saturation_counts, dark_counts=dark_counts,
                                 imbalance_decades=np.inf).mean(axis=0)
    else:
        usable = pol_op_validity(c, pairs, saturation_counts=saturation_counts,
                                 dark_counts=dark_counts).any(axis=-1).mean(axis=0)
    if p == 4:
        same = (c[..., 0] == c[..., 1]) | (c[..., 2] == c[..., 3])
        imb = pair_imbalance(c)
    else:
        same = np.all(c == c[..., :1], axis=-1)
        imb = np.full((n, k), np.nan)
    out = []
    for u in range(k):
        good = lit[:, u] & (c[:, u].max(axis=-1) < saturation_counts)
        blind = float(same[good, u].mean()) if good.any() else float("nan")
        med = float(np.nanmedian(imb[good, u])) if good.any() and np.any(np.isfinite(imb[good, u])) else float("nan")
        reason = ""
        if np.isfinite(blind) and blind > blind_fraction:
            reason = f"polarization-blind: orthogonal photodiodes read identical counts in {blind:.0%} of lit samples"
        elif np.isfinite(med) and abs(med) > imbalance_decades:
            reason = f"bad photodiode: the two POL-OPs' total light differs by a factor {10 ** abs(med):.2f} (median)"
        elif usable[u] < min_usable_fraction:
            reason = f"usable in only {usable[u]:.0%} of samples (saturated {sat[u]:.0%}, dark {dark[u]:.0%})"
        out.append(UnitFault(u, float(sat[u]), float(dark[u]), blind, med, float(usable[u]), bool(reason), reason))
    return out
