"""The spectral5 serial driver against the fake board on a pseudo-terminal."""

import numpy as np
import pytest

from bionav.errors import DeviceError
from bionav.plugins.sensors.fakes.spectral5 import FakeSpectral5
from bionav.plugins.sensors.spectral5 import Spectral5Serial, Spectral5Sim
from bionav.spectral import protocol
from bionav.spectral.protocol import reading_counts, reading_message


def _driver(port, **kw):
    cfg = Spectral5Serial.Config(port=port, timeout_s=kw.pop("timeout_s", 0.3), **kw)
    return Spectral5Serial(cfg)


def test_protocol_parse_and_format():
    assert protocol.parse_reading(b"1,22,333,4095,0,3277\r\n") == (1, 22, 333, 4095, 0, 3277)
    assert protocol.format_reading([1, 2, 3, 4, 5, 6]) == b"1,2,3,4,5,6\r\n"
    for bad in (b"1,2,3,4,5", b"1,2,3,4,5,6,7", b"1,2,3,4,5,4096", b"a,2,3,4,5,6", b"1, 2,3,4,5,6", b""):
        with pytest.raises(protocol.ProtocolError):
            protocol.parse_reading(bad)
    assert protocol.measure_command(10) == b"M10\r"
    with pytest.raises(ValueError):
        protocol.measure_command(0)


def test_measure_and_identify_exact_values():
    expected = np.array([[10, 20, 30, 40, 50, 3277], [4095, 0, 1, 2, 3, 3276], [7, 7, 7, 7, 7, 7]])
    with FakeSpectral5(source=lambda n: expected[:n]) as fake, _driver(fake.port) as drv:
        assert drv.identify() == protocol.IDENT
        np.testing.assert_array_equal(drv.measure(3), expected)
        np.testing.assert_array_equal(drv.measure(1), expected[:1])
        assert fake.commands == [b"?", b"M3", b"M1"]


def test_many_readings_default_source():
    with FakeSpectral5(seed=1) as fake, _driver(fake.port, readings_per_point=200) as drv:
        r = drv.measure()
        assert r.shape == (200, 6) and r.dtype == np.int64
        assert np.all(r[:, 5] == 3277) and abs(r[:, 0].mean() - 2900) < 2


@pytest.mark.parametrize("fault, needle", [
    ("garbage", "garbage line"),
    ("short", "short reply: 4 of 5"),
    ("truncated", "incomplete line"),
    ("silent", "no reply within 0.3 s"),
])
def test_faults_raise_clear_errors_naming_port_and_command(fault, needle):
    with FakeSpectral5(fault=fault) as fake, _driver(fake.port, retries=1) as drv:
        with pytest.raises(DeviceError) as err:
            drv.measure(5)
        msg = str(err.value)
        assert needle in msg and fake.port in msg and "'M5'" in msg
        assert fake.commands.count(b"M5") == 2  # one retry
        # the driver recovers once the device behaves again
        fake.fault = None
        assert drv.measure(2).shape == (2, 6)


def test_a_transient_fault_is_retried():
    with FakeSpectral5() as fake, _driver(fake.port, retries=1) as drv:
        fake.next_faults = ["garbage"]
        assert drv.measure(4).shape == (4, 6)
        fake.next_faults = ["short", "silent"]
        with pytest.raises(DeviceError):
            drv.measure(4)


def test_device_error_reply_is_reported():
    with FakeSpectral5(fault="error") as fake, _driver(fake.port) as drv:
        with pytest.raises(DeviceError, match="adc timeout"):
            drv.measure(3)
        assert fake.commands.count(b"M3") == 1  # an ERR reply is not retried


def test_missing_port_is_a_clear_error(tmp_path):
    with pytest.raises(DeviceError, match="cannot open serial port.*sensor.port"):
        _driver(str(tmp_path / "ttyNOPE")).open()


def test_sim_sensor_and_messages():
    sim = Spectral5Sim(Spectral5Sim.Config(noise_counts=0.0))
    sim.point(0.0, np.deg2rad(60))
    sky = sim.measure(3)
    sim.point(0.0, np.deg2rad(-30))
    ground = sim.measure(1)
    assert sky.shape == (3, 6) and np.all(sky == sky[0])
    # sky brighter than grass in UV, grass brighter than clear sky in IR
    assert sky[0, 0] > ground[0, 0] and ground[0, 4] > sky[0, 4]
    msg = reading_message(sky)
    assert msg["counts"][0][0] == sky[0, 0] and len(msg["counts"]) == 3
    np.testing.assert_array_equal(reading_counts(msg), sky)
    assert sim.read()["counts"][0] == ground[0].tolist()


def test_fake_driven_by_the_simulator():
    sim = Spectral5Sim(Spectral5Sim.Config(noise_counts=0.0))
    sim.point(1.0, 0.5)
    with FakeSpectral5(source=sim.measure) as fake, _driver(fake.port) as drv:
        np.testing.assert_array_equal(drv.measure(2), sim.measure(2))
        assert drv.read() == {"counts": [sim.measure(1)[0].tolist()]}
