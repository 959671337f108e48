"""Triangle-mesh worlds: loading reconstructed habitats from ``.mat``, ``.obj`` and ``.ply`` files.

:func:`load_mesh` is the one entry point. It returns a :class:`TriangleMesh`:
one row per triangle, vertices in metres in a right-handed world frame
(``+z`` up), and one linear colour ``(r, g, b)`` in ``[0, 1]`` per triangle.

File layouts
------------
``.mat`` (MATLAB, the layout of the Seville 2009 ant world of Mangan & Webb
2012 and Baddeley et al. 2012, distributed by InsectRobotics/insectvision):
    ``X``, ``Y``, ``Z``: arrays of shape ``(N, 3)``, the x, y and z of the three
    corners of every triangle in metres; optional ``colp``: ``(N, 3)`` RGB or
    ``(N,)`` / ``(N, 1)`` grey per triangle (default mid grey). As the
    reference renderer ``ImgGrabber_2013.m`` does, heights are taken as
    ``|Z|``: a few corners of that world lie slightly below ``z = 0`` (noise of
    the reconstruction) and the reference renderer folds them up.
``.obj`` / ``.ply`` (read with trimesh, https://trimesh.org):
    any triangle (or polygon: trimesh triangulates) mesh; per-face colours if
    the file has them, else per-vertex colours averaged over each face, else
    mid grey. Scenes with several meshes are concatenated.

Nothing is assumed about units for ``.obj``/``.ply`` beyond "metres": scale a
reconstruction in centimetres before use.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from bionav.errors import UserError

#: File suffixes :func:`load_mesh` reads.
MESH_SUFFIXES = (".mat", ".obj", ".ply")

#: Colour of triangles whose file gives none.
DEFAULT_GREY = 0.5


@dataclass
class TriangleMesh:
    """Triangles of a world, one row each.

    Parameters
    ----------
    triangles : ndarray, shape (N, 3, 3), float64
        ``triangles[i, k]`` is corner ``k`` ``(x, y, z)`` of triangle ``i`` in metres.
    colors : ndarray, shape (N, 3), float64
        Linear RGB in ``[0, 1]`` per triangle.
    source : str
        Where the mesh came from (file path or a description).
    """

    triangles: np.ndarray
    colors: np.ndarray
    source: str = ""
    info: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.triangles = np.ascontiguousarray(self.triangles, dtype=np.float64).reshape(-1, 3, 3)
        self.colors = np.ascontiguousarray(self.colors, dtype=np.float64).reshape(-1, 3)

    def __len__(self) -> int:
        return len(self.triangles)

    @property
    def bounds(self) -> np.ndarray:
        """``[[xmin, ymin, zmin], [xmax, ymax, zmax]]`` in metres, shape (2, 3)."""
        v = self.triangles.reshape(-1, 3)
        return np.stack([v.min(axis=0), v.max(axis=0)])

    @property
    def grey(self) -> np.ndarray:
        """Grey value per triangle (mean of r, g, b), shape (N,)."""
        return self.colors.mean(axis=1)

    def digest(self) -> str:
        """SHA-256 of the triangles and colours (cache keys)."""
        import hashlib

        h = hashlib.sha256()
        h.update(np.ascontiguousarray(self.triangles).tobytes())
        h.update(np.ascontiguousarray(self.colors).tobytes())
        return h.hexdigest()


def mesh_from_arrays(triangles, colors=None, *, source: str = "arrays") -> TriangleMesh:
    """A validated :class:`TriangleMesh` from corner coordinates and optional colours.

    Parameters
    ----------
    triangles : array_like, shape (N, 3, 3)
        Corners in metres.
    colors : array_like, shape (N, 3) or (N,), optional
        RGB or grey per triangle in ``[0, 1]`` (values above 1 are read as 8-bit).
    source : str
        Named in error messages.

    Raises
    ------
    UserError
        No triangles, non-finite corners, or colours of the wrong length.
    """
    tri = np.asarray(triangles, dtype=np.float64)
    if tri.ndim != 3 or tri.shape[1:] != (3, 3):
        raise UserError(f"{source}: triangles must have shape (N, 3, 3), got {tri.shape}; "
                        "give three (x, y, z) corners per triangle.")
    if len(tri) == 0:
        raise UserError(f"{source} holds no triangles; a mesh world needs at least one triangle "
                        "(check that the file is a triangle mesh and not a point cloud).")
    bad = ~np.isfinite(tri).all(axis=(1, 2))
    if bad.any():
        raise UserError(f"{source}: {int(bad.sum())} of {len(tri)} triangles have NaN or infinite corners "
                        f"(first: triangle {int(np.flatnonzero(bad)[0])}); remove them from the mesh or "
                        "fill the holes before rendering.")
    if colors is None:
        col = np.full((len(tri), 3), DEFAULT_GREY)
    else:
        col = np.asarray(colors, dtype=np.float64)
        if col.ndim == 1 or (col.ndim == 2 and col.shape[1] == 1):
            col = np.repeat(col.reshape(-1, 1), 3, axis=1)
        if col.shape != (len(tri), 3):
            raise UserError(f"{source}: {col.shape[0]} colours for {len(tri)} triangles; give one grey or RGB "
                            "colour per triangle.")
        if not np.isfinite(col).all():
            raise UserError(f"{source}: colours contain NaN; give finite colours in [0, 1].")
        if col.max() > 1.0:
            col = col / 255.0
        col = np.clip(col, 0.0, 1.0)
    return TriangleMesh(tri, col, source=source)


def _load_mat(path: Path) -> TriangleMesh:
    import scipy.io

    try:
        data = scipy.io.loadmat(str(path))
    except Exception as exc:  # scipy raises ValueError, TypeError, MatReadError ... for non-MAT files
        raise UserError(f"{path} is not a readable MATLAB .mat file ({type(exc).__name__}: {exc}); "
                        "give a .mat file holding X, Y, Z (N x 3, metres) and optional colp.") from None
    keys = sorted(k for k in data if not k.startswith("__"))
    missing = [k for k in ("X", "Y", "Z") if k not in data]
    if missing:
        raise UserError(f"{path} is not a mesh world: it lacks the variable(s) {', '.join(missing)} "
                        f"(it holds: {', '.join(keys) or 'nothing'}). A .mat mesh needs X, Y, Z of shape "
                        "(N, 3), the corners of N triangles in metres, and optionally colp.")
    try:
        xyz = [np.asarray(data[k], dtype=np.float64) for k in ("X", "Y", "Z")]
    except (TypeError, ValueError):
        raise UserError(f"{path}: X, Y, Z must be numeric arrays of shape (N, 3).") from None
    shapes = {a.shape for a in xyz}
    if len(shapes) != 1 or xyz[0].ndim != 2 or xyz[0].shape[1] != 3:
        if len(shapes) == 1 and xyz[0].ndim == 2 and xyz[0].shape[0] == 3 and xyz[0].shape[1] != 3:
            xyz = [a.T for a in xyz]  # stored as 3 x N (MATLAB patch layout)
        else:
            raise UserError(f"{path}: X, Y, Z have shapes {[a.shape for a in xyz]}; each must be (N, 3), "
                            "one row per triangle.")
    tri = np.stack([xyz[0], xyz[1], np.abs(xyz[2])], axis=-1)  # |Z| as the reference renderer
    colors = data.get("colp")
    if colors is not None:
        colors = np.asarray(colors, dtype=np.float64)
        if colors.ndim == 2 and colors.shape[0] in (1, 3) and colors.shape[1] == len(tri) and len(tri) != 3:
            colors = colors.T
    mesh = mesh_from_arrays(tri, colors, source=str(path))
    mesh.info["layout"] = "mat"
    return mesh


def _load_trimesh(path: Path) -> TriangleMesh:
    try:
        import trimesh
    except ImportError:  # pragma: no cover - trimesh is a dependency
        raise UserError("reading .obj/.ply meshes needs the trimesh package: pip install trimesh") from None
    try:
        loaded = trimesh.load(str(path), force="mesh", process=False)
    except Exception as exc:  # trimesh raises many types for garbage input
        raise UserError(f"{path} is not a readable {path.suffix} mesh ({type(exc).__name__}: {exc}); "
                        "give a triangle mesh in .obj or .ply format.") from None
    faces = getattr(loaded, "faces", None)
    vertices = getattr(loaded, "vertices", None)
    if faces is None or vertices is None or len(faces) == 0:
        raise UserError(f"{path} holds no triangles (a point cloud or an empty file?); a mesh world needs "
                        "faces. Reconstruct a surface (e.g. Poisson reconstruction) and save it as .obj or .ply.")
    vertices = np.asarray(vertices, dtype=np.float64)
    faces = np.asarray(faces, dtype=np.int64)
    bad = np.flatnonzero(np.any((faces < 0) | (faces >= len(vertices)), axis=tuple(range(1, faces.ndim))))
    if bad.size:
        first = faces[bad[0]]
        vertex = int(first.min() if first.min() < 0 else first.max())
        raise UserError(f"{path}: face {int(bad[0])} names vertex {vertex}, "
                        f"but the file has vertices 0..{len(vertices) - 1} ({bad.size} such faces); the file is "
                        "damaged: re-export it from the program that made it.")
    tri = vertices[faces]
    colors = None
    visual = getattr(loaded, "visual", None)
    kind = getattr(visual, "kind", None)
    try:
        if kind == "face":
            colors = np.asarray(visual.face_colors, dtype=np.float64)[:, :3] / 255.0
        elif kind == "vertex":
            colors = np.asarray(visual.vertex_colors, dtype=np.float64)[faces, :3].mean(axis=1) / 255.0
        elif kind == "texture":
            colors = np.asarray(visual.to_color().vertex_colors, dtype=np.float64)[faces, :3].mean(axis=1) / 255.0
    except Exception:  # a broken material falls back to grey rather than failing the load
        colors = None
    mesh = mesh_from_arrays(tri, colors, source=str(path))
    mesh.info["layout"] = path.suffix.lower().lstrip(".")
    return mesh


def load_mesh(path) -> TriangleMesh:
    """Read a triangle-mesh world from a ``.mat``, ``.obj`` or ``.ply`` file.

    Parameters
    ----------
    path : str or Path
        The file (see the module docstring for the layouts).

    Returns
    -------
    TriangleMesh
        Corners in metres (``.mat``: ``|Z|``), one RGB colour per triangle.

    Raises
    ------
    UserError
        Missing file, unknown suffix, a file that is not a mesh, no triangles,
        NaN corners -- each with what was expected.
    """
    from bionav.files import not_a_regular_file

    p = Path(path).expanduser()
    if not p.exists():
        raise UserError(f"mesh file {p} does not exist; give db.path=FILE with a {', '.join(MESH_SUFFIXES)} mesh.")
    if p.is_dir():
        raise UserError(f"mesh path {p} is a folder; give db.path=FILE pointing at a {', '.join(MESH_SUFFIXES)} file.")
    problem = not_a_regular_file(p)  # a FIFO or a device would block the reader or never end
    if problem is not None:
        raise UserError(f"mesh file {p} {problem}; give db.path=FILE pointing at a {', '.join(MESH_SUFFIXES)} file.")
    from bionav.datafile import checked_path

    checked_path(p, what="mesh file", kind="mesh", fix=f"Give db.path=FILE pointing at a {', '.join(MESH_SUFFIXES)} "
                 "file of a world (decimate a larger reconstruction, e.g. with MeshLab).")
    suffix = p.suffix.lower()
    if suffix == ".mat":
        return _load_mat(p)
    if suffix in (".obj", ".ply"):
        return _load_trimesh(p)
    raise UserError(f"{p}: unknown mesh format {suffix or '(no suffix)'!r}; bionav reads "
                    f"{', '.join(MESH_SUFFIXES)} (convert other formats, e.g. with trimesh or MeshLab).")
