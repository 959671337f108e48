"""Drivers against fake devices on pseudo-terminals, including every fault.

The drivers open the pty's slave side like any serial port; the fakes serve
the device protocols from a thread (bionav.plugins.sensors.fakes).
"""

import os
import time

import pytest

from bionav.errors import DeviceError
from bionav.plugins.sensors.fakes.dlpio8 import FakeDLPIO8
from bionav.plugins.sensors.fakes.ptu46 import RESOLUTION_ARCSEC, FakePTU46
from bionav.plugins.sensors.fakes.tcm2 import FakeTCM2
from bionav.plugins.sensors.polcompass_serial import PolCompassSerial, PolCompassSerialConfig
from bionav.plugins.sensors.ptu46 import PTU46, PTU46Config
from bionav.plugins.sensors.tcm2 import TCM2, TCM2Config
from bionav.plugins.sensors.tcm2_protocol import TCM2FormatError, checksum, format_nmea, format_standard, parse_line

FAST = {"timeout_s": 0.15, "reconnect_attempts": 1, "reconnect_delay_s": 0.01}


def counts_by_line(line):
    return [0, 101, 513, 1023, 7, 8, 9, 10, 11][line]


@pytest.fixture
def dlp():
    with FakeDLPIO8(counts_by_line) as fake:
        sensor = PolCompassSerial(PolCompassSerialConfig(port=fake.port, **FAST))
        sensor.open()
        yield fake, sensor
        sensor.close()


def test_dlp_binary_protocol(dlp):
    fake, sensor = dlp
    assert sensor.read() == {"counts": [101, 513, 1023], "lines": [1, 2, 3]}
    # '\' once at start, then one analog command per line: Z X C for lines 1-3.
    assert fake.received == [b"\\", b"Z", b"X", b"C"]
    sensor.lines = [8, 4]
    assert sensor.read()["counts"] == [11, 7]
    assert fake.received[-2:] == [b",", b"V"]


@pytest.mark.parametrize(
    "fault, message",
    [("silent", "did not answer within 0.15 s"), ("garbage", "sent garbage"), ("short", "short reply (1 of 2 bytes")],
)
def test_dlp_faults_name_port_and_command(dlp, fault, message):
    fake, sensor = dlp
    fake.inject(fault, on=b"X")  # line 1 fine, line 2 faulty
    with pytest.raises(DeviceError) as err:
        sensor.read()
    text = str(err.value)
    assert message in text and fake.port in text and "'X (analog line 2)'" in text


def test_dlp_unplug_mid_reading_aborts_cleanly(dlp):
    fake, sensor = dlp
    sensor.read()
    fake.inject("unplug", on=b"C")  # while reading line 3
    with pytest.raises(DeviceError) as err:
        sensor.read()
    assert "connection was lost" in str(err.value) and fake.port in str(err.value) and "line 3" in str(err.value)
    assert sensor._link is None or not sensor._link.is_open  # closed after the failed reconnect
    assert not os.path.exists(fake.port)  # the device is gone


def test_missing_and_busy_ports():
    with pytest.raises(DeviceError, match=r"/dev/no-such-tty does not exist.*sensor\.port="):
        PolCompassSerial(PolCompassSerialConfig(port="/dev/no-such-tty", **FAST)).open()
    with FakeDLPIO8(counts_by_line) as fake:
        first = PolCompassSerial(PolCompassSerialConfig(port=fake.port, **FAST))
        first.open()
        try:
            with pytest.raises(DeviceError, match="busy"):
                PolCompassSerial(PolCompassSerialConfig(port=fake.port, **FAST)).open()
        finally:
            first.close()


@pytest.fixture
def ptu():
    moves = []
    with FakePTU46(lambda p, t: moves.append((p, t))) as fake:
        unit = PTU46(PTU46Config(port=fake.port, settle_s=0.03, **FAST))
        unit.open()
        yield fake, unit, moves
        unit.close()


def test_ptu_initialisation_and_moves(ptu):
    fake, unit, moves = ptu
    assert fake.received[:2] == [b"ED", b"FT"] and fake.terse and not fake.echo_on
    res = RESOLUTION_ARCSEC / 3600.0 * 3.141592653589793 / 180.0
    assert unit.resolution() == pytest.approx((res, res))
    assert unit.limits() == pytest.approx((-3090 * res, 3090 * res, -907 * res, 604 * res))
    state = unit.move_to(0.5, -0.2)
    assert state["pan_pos"] == round(0.5 / res) and state["tilt_pos"] == round(-0.2 / res)
    assert state["pan"] == pytest.approx(state["pan_pos"] * res)
    assert fake.received[-5:] == [f"PP{state['pan_pos']}".encode(), f"TP{state['tilt_pos']}".encode(), b"A", b"PP", b"TP"]
    assert moves[-1] == pytest.approx((state["pan"], state["tilt"]))


def test_ptu_out_of_range_move_is_refused_before_sending(ptu):
    fake, unit, _ = ptu
    n = len(fake.received)
    with pytest.raises(DeviceError) as err:
        unit.move_to(3.0, 0.0)
    assert "outside its limits" in str(err.value) and "PP3342" in str(err.value) and fake.port in str(err.value)
    assert len(fake.received) == n


def test_ptu_reports_device_range_error():
    # A unit whose real limits are narrower than the ones it reported: the device's '!' reaches the user.
    with FakePTU46(limits=(-3090, 3090, -907, 604)) as fake:
        unit = PTU46(PTU46Config(port=fake.port, settle_s=0.03, **FAST))
        unit.open()
        fake.limits = (-100, 100, -907, 604)
        with pytest.raises(DeviceError, match=r"Maximum allowable Pan position is 100.*'PP557 '"):
            unit.move_to(0.5, 0.0)
        unit.close()


@pytest.mark.parametrize(
    "fault, message",
    [
        ("error", "reported an error: '! Illegal command argument'"),
        ("garbage", "sent garbage"),
        ("short", "incomplete line"),
        ("silent", "did not answer"),
    ],
)
def test_ptu_faults(ptu, fault, message):
    fake, unit, _ = ptu
    fake.inject(fault, on=b"PP111")
    with pytest.raises(DeviceError) as err:
        unit.move_to(0.1, 0.0)
    assert message in str(err.value) and fake.port in str(err.value) and "PP111" in str(err.value)


def test_ptu_unplug_mid_scan(ptu):
    fake, unit, _ = ptu
    unit.move_to(0.1, 0.0)
    fake.inject("unplug", on=b"A")  # during the next move's await
    with pytest.raises(DeviceError, match="connection was lost.*'A '"):
        unit.move_to(0.2, 0.0)


def test_tcm2_checksum_hand_value_and_formats():
    # The classic NMEA example sentence has checksum 0x47.
    assert checksum("GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,") == 0x47
    line = format_standard(heading_deg=328.3, pitch_deg=28.4, roll_deg=-12.4, temperature_c=22.3)
    assert line.startswith("$C328.3P28.4R-12.4T22.3*") and line.endswith("\r\n")
    want = {"format": "standard", "heading_deg": 328.3, "pitch_deg": 28.4, "roll_deg": -12.4, "temperature_c": 22.3}
    assert parse_line(line) == want
    assert parse_line(format_nmea(heading_deg=182.3)) == {"format": "nmea", "heading_deg": 182.3}
    with pytest.raises(TCM2FormatError) as err:
        parse_line(line.replace("*", "*0" if not line.split("*")[1].startswith("0") else "*1")[:-3] + "\r\n")
    assert err.value.kind in ("checksum", "garbage")
    with pytest.raises(TCM2FormatError, match="checksum") as err:
        body = "C100.0T20.0"
        parse_line(f"${body}*{checksum(body) ^ 1:02X}")
    assert err.value.kind == "checksum"
    with pytest.raises(TCM2FormatError) as err:
        parse_line("$Cxyz*00")
    assert err.value.kind in ("garbage", "checksum")


@pytest.fixture
def tcm2():
    with FakeTCM2(lambda: (123.4, 1.0, -2.0)) as fake:
        compass = TCM2(TCM2Config(port=fake.port, **FAST))
        compass.open()
        yield fake, compass
        compass.close()


def test_tcm2_reads_and_switches_format(tcm2):
    fake, compass = tcm2
    reading = compass.read()
    assert reading["heading_deg"] == 123.4 and reading["pitch_deg"] == 1.0 and reading["format"] == "standard"
    assert reading["line"].startswith("$C123.4P1.0R-2.0")
    assert fake.received[:2] == [b"h", b"sdo=t"]
    fake.nmea = True
    assert compass.read() == {
        "line": "$HCHDM,123.4,M*" + f"{checksum('HCHDM,123.4,M'):02X}",
        "format": "nmea",
        "heading_deg": 123.4,
    }


def test_tcm2_ignores_stale_streamed_words():
    headings = iter(range(1000))
    with FakeTCM2(lambda: (float(next(headings)), 0.0, 0.0)) as fake:
        fake.streaming = True  # a TCM2 left in continuous mode ('go') by someone else
        time.sleep(0.1)
        compass = TCM2(TCM2Config(port=fake.port, **FAST))
        compass.open()  # halts the stream and drains it
        assert not fake.streaming
        first = compass.read()["heading_deg"]
        assert compass.read()["heading_deg"] == first + 1  # each query answered by a fresh word
        compass.close()


@pytest.mark.parametrize(
    "fault, message",
    [("checksum", "wrong checksum"), ("garbage", "sent garbage"), ("short", "incomplete line"), ("silent", "did not answer")],
)
def test_tcm2_faults(tcm2, fault, message):
    fake, compass = tcm2
    fake.inject(fault, on=b"s?")
    with pytest.raises(DeviceError) as err:
        compass.read()
    assert message in str(err.value) and fake.port in str(err.value) and "'s?'" in str(err.value)
    time.sleep(0.05)
    assert compass.read()["heading_deg"] == 123.4  # the next reading is fine again


def test_tcm2_unplug(tcm2):
    fake, compass = tcm2
    fake.inject("unplug", on=b"s?")
    with pytest.raises(DeviceError, match="connection was lost"):
        compass.read()
