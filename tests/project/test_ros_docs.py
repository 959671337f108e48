"""docs/ros.md: every command in it runs for real through ``python -m bionav...`` on the bag the page uses.

The bag, ``robot.bag``, is written by rosbags' writer (``rosbag_helpers.robot_bag``); ``RUN`` is a real
grid-homing run on it. The command that names only the bag must fail cleanly and list its topics; every
other command must succeed. (tests/project/test_documented_commands.py composes the same commands too.)
"""

from __future__ import annotations

import shlex
import socket

import pytest
from helpers import assert_fails_cleanly, run_bionav
from test_documented_commands import _is_syntax_line, documented_commands

pytest.importorskip("rosbags")
pytest.importorskip("foxglove")


def ros_commands():
    return [c for c in documented_commands() if c.file == "docs/ros.md" and not _is_syntax_line(c.text)]


def test_the_page_has_its_commands():
    texts = [c.text for c in ros_commands()]
    assert any("db=bag" in t and "db.grid_cell_m" in t for t in texts)  # the homing table
    assert any("experiment=route_homing" in t and "db=bag" in t for t in texts)  # the route-following table
    assert any(t.startswith("python -m bionav.logs export-ros2") for t in texts)
    assert any("bionav.live=" in t for t in texts)
    assert any("reference.name=bag" in t for t in texts)


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.mark.slow
def test_every_command_of_ros_md_runs(tmp_path):
    from rosbag_helpers import robot_bag

    robot_bag(tmp_path / "robot")
    proc = run_bionav("db=bag", "db.path=robot.bag", "db.image_topic=/camera/image", "db.pose_topic=/odom",
                      "db.grid_cell_m=0.3", "experiment.log_views=true", "hydra.run.dir=RUN", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    failures = []
    for k, cmd in enumerate(ros_commands()):
        words = shlex.split(cmd.text)
        module, args = words[2], words[3:]
        if module == "bionav":
            args = [f"bionav.live={_free_port()}" if a.startswith("bionav.live=") else a for a in args]
            args.append(f"hydra.run.dir=outputs/doc{k}")
        elif module == "bionav.bench":
            args += ["--bag-gb", "0.01", "--bag-frame", "64", "48", "--bag-unfold", "32", "8"]  # a small bag, quickly
        elif len(args) <= 1:  # a mention of a sub-command in the prose
            args.append("--help")
        proc = run_bionav(*args, module=module, cwd=tmp_path)
        if module == "bionav" and not any(a.startswith("db.image_topic=") for a in args) and "db=bag" in args:
            assert_fails_cleanly(proc, "db.image_topic and db.pose_topic are not set",
                                 "/camera/image (sensor_msgs/msg/Image, 57 messages)", "/tf (tf2_msgs/msg/TFMessage")
            continue
        if proc.returncode != 0 or "Traceback" in proc.stderr:
            failures.append(f"{cmd.where()}\n  exit {proc.returncode}: {proc.stderr.strip().splitlines()[-3:]}")
    assert not failures, "\n".join(failures)
    assert (tmp_path / "RUN_ros2" / "metadata.yaml").is_file()
