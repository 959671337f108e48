"""The sun at each sample's time (issue 41): the time base, the ephemeris track and the decoding against it."""

import datetime as dt

import numpy as np
import pytest

from bionav.geometry import wrap_angle
from bionav.light import parse_time, sun_position, sun_track
from bionav.polcompass.timebase import sample_times
from bionav.testing.polcompass import write_model_session

SITE = {"latitude_deg": 39.2, "longitude_deg": 9.1}


def test_sample_times_spread_each_rotation_evenly_over_its_period():
    # hand-computed: rotation r starts at r T, its n samples are T / n apart
    np.testing.assert_allclose(sample_times([0, 0, 0, 0, 1, 1], 72.0), [0.0, 18.0, 36.0, 54.0, 72.0, 108.0])
    np.testing.assert_allclose(sample_times([0, 0, 1, 1, 1], 0.0), 0.0)  # a period of 0: all at the start
    assert sample_times([], 72.0).shape == (0,)


def test_the_sun_track_is_the_ephemeris_at_each_time():
    start = "2022-05-12T13:00:00+02:00"
    offsets = np.array([0.0, 17.0, 250.0, 3600.0, -90.0])
    azimuth, elevation = sun_track(start, offsets, **SITE)
    for s, a, e in zip(offsets, azimuth, elevation):
        p = sun_position(parse_time(start) + dt.timedelta(seconds=float(s)), **SITE)
        # stated: linear interpolation between 30 s ephemeris nodes is within 0.001 degrees
        assert abs(np.degrees(wrap_angle(a - p.azimuth))) < 1e-3
        assert abs(np.degrees(e - p.elevation)) < 1e-3
    # near noon at 69 degrees the sun moves about a degree a minute: an hour is tens of degrees, continuous
    assert 10.0 < abs(np.degrees(azimuth[3] - azimuth[0])) < 60.0


@pytest.mark.parametrize("sun", ["sample", "session"])
def test_each_sample_is_decoded_against_the_sun_at_its_own_time(tmp_path, sun):
    from bionav.plugins.decoders.sky_fit import SkyFit, SkyFitConfig
    from bionav.polcompass.recordings_config import recordings_config
    from bionav.polcompass.sessions import decode_session, prepared_sessions

    n, period = 60, 72.0
    folder = tmp_path / "tod_data" / "Thursday_12-05-22" / "13-00__Thursday_12-05-22"
    write_model_session(folder, rotations=3, samples=n, mount_deg=30.0, rotation_period_s=period, blind_unit=None)
    rc = recordings_config({"path": str(tmp_path), "sun": sun, "rotation_period_s": period})
    prepared, bad = prepared_sessions(rc)
    assert not bad and len(prepared) == 1
    data = prepared[0]
    # hand-computed time base: sample i of rotation r is (r + i / n) T after 11:00 UTC (13:00 CEST)
    start = dt.datetime(2022, 5, 12, 11, 0, tzinfo=dt.timezone.utc)
    picks = np.array([0, 30, n + 15, 2 * n + 59])
    seconds = [(k // n + (k % n) / n) * period for k in picks]
    expected = np.array([sun_position(start + dt.timedelta(seconds=s), **SITE).azimuth for s in seconds])
    first = sun_position(start, **SITE).azimuth
    want = expected if sun == "sample" else np.full(picks.size, first)
    np.testing.assert_allclose(np.degrees(wrap_angle(data.sun_azimuth[picks] - want)), 0.0, atol=1e-3)
    # the decoded heading against the written truth (mount + the logged yaw: no restarts): one constant under the
    # sun of each sample; under one sun per session it drifts by the sun's own motion since the start
    heading = decode_session(SkyFit(SkyFitConfig()), data)[0]
    truth = np.deg2rad(30.0) + data.yaw
    err = np.degrees(wrap_angle(heading - truth))
    drift = err[picks] - err[0]
    sun_moved = np.degrees(wrap_angle(expected - first))
    assert abs(sun_moved[-1]) > 2.0  # over the 3.6 minutes the sun turned by more than two degrees
    if sun == "sample":
        assert np.max(np.abs(err)) < 0.25 and np.mean(np.abs(err)) < 0.05  # the counts' rounding
    else:
        np.testing.assert_allclose(drift, -sun_moved, atol=0.05)
