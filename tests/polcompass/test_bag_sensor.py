"""sensor=bag: Imu / MagneticField headings and image topics of a rosbags-written bag as sensor readings."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from helpers import assert_fails_cleanly, run_bionav
from rosbag_helpers import T0_NS, BagWriter

pytest.importorskip("rosbags")

from bionav.errors import UserError  # noqa: E402
from bionav.plugins.sensors.bag import BagSensor, BagSensorConfig, reading_image  # noqa: E402


def _imu_bag(path, yaws, container="mcap", *, field=True, image=None):
    w = BagWriter(path, container)
    for k, yaw in enumerate(yaws):
        t = T0_NS + k * 10**8
        w.put("/imu/data", t, w.imu(t, yaw))
        if field:  # a level magnetometer: the horizontal field points to magnetic north
            w.put("/imu/mag", t, w.magnetic_field(t, (2e-5 * math.sin(yaw), 2e-5 * math.cos(yaw), -4e-5)))
        if image is not None and k < 2:
            w.put("/camera/image", t, w.image(t, image, "mono16" if image.dtype == np.uint16 else "png"))
    return w.close()


@pytest.mark.parametrize("container", ["ros1", "sqlite3", "mcap"])
def test_imu_and_magnetometer_headings(tmp_path, container):
    yaws = [0.0, math.pi / 2, -math.pi / 4, 3.0]
    bag = _imu_bag(tmp_path / "imu", yaws, container)
    for topic in ("/imu/data", "/imu/mag"):
        sensor = BagSensor(BagSensorConfig(path=str(bag), topic=topic))
        with sensor:
            readings = [sensor.read() for _ in yaws]
            with pytest.raises(UserError, match="has played all 4 messages of " + topic):
                sensor.read()
        assert sensor.schema_name == ("bionav.ImuReading" if topic == "/imu/data" else "bionav.MagneticFieldReading")
        # yaw CCW from east; bearing clockwise from north: 0 -> 90, pi/2 -> 0, -pi/4 -> 135, 3 rad -> 90 - 171.9
        assert [r["yaw"] for r in readings] == pytest.approx(yaws, abs=1e-12)
        assert [r["heading_deg"] for r in readings] == pytest.approx(
            [90.0, 0.0, 135.0, (90.0 - math.degrees(3.0)) % 360.0], abs=1e-9)
        assert [r["stamp_ns"] for r in readings] == [T0_NS + k * 10**8 for k in range(4)]
        json.dumps(readings)  # JSON-ready as the log wants them


def test_loop_images_and_topic_errors(tmp_path):
    view = (np.arange(8 * 24, dtype=np.uint16).reshape(8, 24) * 300)
    bag = _imu_bag(tmp_path / "cam", [0.1, 0.2, 0.3], image=view)
    sensor = BagSensor(BagSensorConfig(path=str(bag), topic="/camera/image", loop=True))
    with sensor:
        first, second, again = sensor.read(), sensor.read(), sensor.read()
    assert sensor.schema_name == "foxglove.RawImage" and first["encoding"] == "mono16"
    assert again == first and second["timestamp"]["nsec"] == 10**8
    assert np.array_equal(reading_image(first), view.astype(np.float32) / np.float32(65535))
    with pytest.raises(UserError, match=r"sensor.topic=/imu/dat: .*Did you mean sensor.topic=/imu/data\?"):
        BagSensor(BagSensorConfig(path=str(bag), topic="/imu/dat")).open()
    with pytest.raises(UserError, match=r"sensor.topic is not set.*/imu/data \(sensor_msgs/msg/Imu, 3 messages\)"):
        BagSensor(BagSensorConfig(path=str(bag))).open()


def _pans(run_dir):
    from bionav.logs.reader import read_messages

    return [m["pan"] for _t, _n, m in read_messages(run_dir / "run.mcap", topics=["/pantilt/state"])]


@pytest.mark.slow
def test_bag_as_the_reference_compass_of_pol_compass(tmp_path):
    """experiment=pol_compass mode=vs_em_compass with the IMU of a bag as its reference compass: the readings
    recorded are the bag's, two runs agree exactly, and the polarized-light compass agrees with the bag."""
    from bionav.logs.reader import read_messages

    common = ("experiment=pol_compass", "mode=vs_em_compass", "experiment.vs_em.positions=8",
              "experiment.vs_em.samples=3")
    sim = run_bionav(*common, f"hydra.run.dir={tmp_path / 'sim'}", cwd=tmp_path)
    assert sim.returncode == 0, sim.stderr
    pans = _pans(tmp_path / "sim")
    yaws = [p + 0.3 for p in pans for _ in range(3)]  # the robot's IMU: the pan plus a mounting offset
    bag = _imu_bag(tmp_path / "imu", yaws, "ros1", field=False)
    ref = ("experiment.reference.name=bag", f"+experiment.reference.path={bag}", "+experiment.reference.topic=/imu/data")
    runs = [run_bionav(*common, *ref, f"hydra.run.dir={tmp_path / f'bag{i}'}", cwd=tmp_path) for i in range(2)]
    for proc in runs:
        assert proc.returncode == 0, proc.stderr
    metrics = [json.loads((tmp_path / f"bag{i}" / "metrics.json").read_text()) for i in range(2)]
    assert {k: v for k, v in metrics[0].items() if k != "wall_time_s"} == \
        {k: v for k, v in metrics[1].items() if k != "wall_time_s"}
    recorded = [m for _t, _n, m in read_messages(tmp_path / "bag0" / "run.mcap", topics=["/reference/raw"])]
    assert [m["yaw"] for m in recorded] == pytest.approx([math.atan2(math.sin(y), math.cos(y)) for y in yaws])
    sim_metrics = json.loads((tmp_path / "sim" / "metrics.json").read_text())
    assert metrics[0]["averaged_rmse_deg"] < sim_metrics["averaged_rmse_deg"] + 2.0
    # a missing topic through the user's door
    proc = run_bionav(*common, "experiment.reference.name=bag", f"+experiment.reference.path={bag}",
                      "+experiment.reference.topic=/imu/mag", f"hydra.run.dir={tmp_path / 'bad'}", cwd=tmp_path)
    assert_fails_cleanly(proc, "experiment.reference.topic=/imu/mag", "has no topic", "/imu/data")
