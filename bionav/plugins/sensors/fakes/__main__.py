"""Serve fake serial devices on pseudo-terminals under one simulated scene until interrupted.

``python -m bionav.plugins.sensors.fakes`` (``--scene polcompass``, the default)
serves a DLP-IO8-G polarized-light compass, a PTU-46 and a TCM2 under one
simulated sky; ``--scene spectral`` serves a five-channel sensor board and a
PTU-46 looking into one simulated backyard. Each device's pseudo-terminal is
printed as the override that selects it (``sensor.port=...``,
``pantilt.port=...``); Ctrl-C stops.
"""

from __future__ import annotations

import argparse
import signal
import sys
import time


def _polcompass_fakes(args) -> dict:
    import numpy as np

    from bionav.light import SkyModel, SunPosition, max_degree_from_turbidity
    from bionav.plugins.sensors.fakes.dlpio8 import CompassCounts, FakeDLPIO8
    from bionav.plugins.sensors.fakes.ptu46 import FakePTU46
    from bionav.plugins.sensors.fakes.tcm2 import FakeTCM2
    from bionav.plugins.sensors.polcompass_sim import PolCompassSimConfig, build_hardware
    from bionav.plugins.sensors.tcm2_sim import simulated_attitude
    from bionav.polcompass import CompassScene

    sky = SkyModel(
        SunPosition(np.deg2rad(args.sun_azimuth_deg), np.deg2rad(args.sun_elevation_deg)),
        max_degree=max_degree_from_turbidity(args.turbidity),
    )
    scene = CompassScene(sky, mount_heading=np.deg2rad(args.mount_heading_deg))
    rng_dlp, rng_tcm2 = np.random.default_rng(args.seed).spawn(2)
    hardware = build_hardware(PolCompassSimConfig())
    return {
        "sensor=polcompass_serial sensor.port": FakeDLPIO8(CompassCounts(hardware, scene, rng_dlp)),
        "pantilt=ptu46 pantilt.port": FakePTU46(scene.set_pose),
        "sensor=tcm2 sensor.port": FakeTCM2(lambda: simulated_attitude(scene, rng_tcm2, noise_deg=0.3)),
    }


def _spectral_fakes(args) -> dict:
    from bionav.light.clouds import CloudLayer
    from bionav.light.daylight import SkyState
    from bionav.plugins.sensors.fakes.ptu46 import FakePTU46
    from bionav.plugins.sensors.fakes.spectral5 import FakeSpectral5
    from bionav.plugins.sensors.spectral5 import Spectral5Sim
    from bionav.world.worlds.garden import backyard_scene

    clouds = CloudLayer(cover=args.cloud_cover, optical_depth=args.cloud_optical_depth, seed=args.seed)
    scene = backyard_scene(SkyState.from_time(args.time, clouds=clouds), seed=args.seed)
    sim = Spectral5Sim(Spectral5Sim.Config(seed=args.seed))
    sim.attach_simulation(scene, None)
    return {
        "sensor=spectral5_serial sensor.port": FakeSpectral5(source=sim.measure, seed=args.seed),
        "pantilt=ptu46 pantilt.port": FakePTU46(scene.set_pose),
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m bionav.plugins.sensors.fakes",
        description=__doc__.splitlines()[0],
        epilog="polcompass: DLP-IO8-G, PTU-46, TCM2 under a sky model (experiment=pol_compass); "
        "spectral: five-channel board and PTU-46 in the backyard (experiment=contrast_scan).",
    )
    parser.add_argument("--scene", choices=("polcompass", "spectral"), default="polcompass",
                        help="which devices to serve (default: polcompass)")
    parser.add_argument("--seed", type=int, default=0)
    polcompass = parser.add_argument_group("--scene polcompass")
    polcompass.add_argument("--sun-elevation-deg", type=float, default=30.0)
    polcompass.add_argument("--sun-azimuth-deg", type=float, default=0.0, help="counter-clockwise from east")
    polcompass.add_argument("--turbidity", type=float, default=1.25)
    polcompass.add_argument("--mount-heading-deg", type=float, default=20.0)
    spectral = parser.add_argument_group("--scene spectral")
    spectral.add_argument("--time", default="2009-06-17T11:27:04+02:00", help="ISO 8601 time with zone")
    spectral.add_argument("--cloud-cover", type=float, default=0.6)
    spectral.add_argument("--cloud-optical-depth", type=float, default=30.0)
    args = parser.parse_args(argv)

    # Ctrl-C (SIGINT) is how this server stops: started from a script in the background, a shell
    # may hand it SIGINT ignored, and Python keeps it so; take it back
    signal.signal(signal.SIGINT, signal.default_int_handler)
    fakes = (_spectral_fakes if args.scene == "spectral" else _polcompass_fakes)(args)
    try:
        for label, fake in fakes.items():
            fake.start()
            print(f"{fake.name:12s} {label}={fake.port}", flush=True)
        print("serving; Ctrl-C stops", file=sys.stderr, flush=True)
        while True:
            time.sleep(1.0)
    except KeyboardInterrupt:
        pass
    finally:
        for fake in fakes.values():
            fake.stop()
    return 0


if __name__ == "__main__":
    sys.exit(main())
