"""Hostile mesh files for ``python -m bionav db=mesh db.path=FILE`` (issue 32): a .ply face naming a
vertex out of range or negative (which used to crash, or silently wrap around), and a FIFO named like a
mesh (which would block the reader)."""

from __future__ import annotations

import os

import pytest
from helpers import assert_fails_cleanly, run_bionav

HEADER = ("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
          "element face {n}\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n")


@pytest.mark.parametrize("faces, needle", [(["3 0 1 2", "3 0 1 7"], "face 1 names vertex 7"),
                                           (["3 0 -1 2"], "face 0 names vertex -1")])
@pytest.mark.slow
def test_a_face_naming_a_missing_vertex(tmp_path, faces, needle):
    path = tmp_path / "world.ply"
    path.write_text(HEADER.format(n=len(faces)) + "\n".join(faces) + "\n")
    proc = run_bionav("db=mesh", f"db.path={path}", f"hydra.run.dir={tmp_path / 'run'}", cwd=tmp_path)
    assert_fails_cleanly(proc, str(path), needle, "vertices 0..2", "re-export", code=2, max_seconds=120)


@pytest.mark.slow
def test_a_fifo_named_like_a_mesh(tmp_path):
    path = tmp_path / "world.ply"
    os.mkfifo(path)
    proc = run_bionav("db=mesh", f"db.path={path}", f"hydra.run.dir={tmp_path / 'run'}", cwd=tmp_path, timeout=300)
    assert_fails_cleanly(proc, str(path), "FIFO", "db.path=FILE", code=2, max_seconds=120)
