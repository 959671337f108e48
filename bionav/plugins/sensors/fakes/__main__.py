"""Serve fake DLP-IO8-G, PTU-46 and TCM2 devices under one simulated sky until interrupted."""

from __future__ import annotations

import argparse
import sys
import time


def main(argv: list[str] | None = None) -> int:
    import numpy as np

    from bionav.plugins.sensors.fakes.dlpio8 import CompassCounts, FakeDLPIO8
    from bionav.plugins.sensors.fakes.ptu46 import FakePTU46
    from bionav.plugins.sensors.fakes.tcm2 import FakeTCM2
    from bionav.plugins.sensors.polcompass_sim import PolCompassSimConfig, build_hardware
    from bionav.plugins.sensors.tcm2_sim import simulated_attitude
    from bionav.polcompass import CompassScene
    from bionav.sky import SkyModel, SunPosition, max_degree_from_turbidity

    parser = argparse.ArgumentParser(prog="python -m bionav.plugins.sensors.fakes", description=__doc__)
    parser.add_argument("--sun-elevation-deg", type=float, default=30.0)
    parser.add_argument("--sun-azimuth-deg", type=float, default=0.0, help="counter-clockwise from east")
    parser.add_argument("--turbidity", type=float, default=1.25)
    parser.add_argument("--mount-heading-deg", type=float, default=20.0)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)

    sky = SkyModel(
        SunPosition(np.deg2rad(args.sun_azimuth_deg), np.deg2rad(args.sun_elevation_deg)),
        max_degree=max_degree_from_turbidity(args.turbidity),
    )
    scene = CompassScene(sky, mount_heading=np.deg2rad(args.mount_heading_deg))
    rng_dlp, rng_tcm2 = np.random.default_rng(args.seed).spawn(2)
    hardware = build_hardware(PolCompassSimConfig())
    fakes = {
        "sensor=polcompass_serial sensor.port": FakeDLPIO8(CompassCounts(hardware, scene, rng_dlp)),
        "pantilt=ptu46 pantilt.port": FakePTU46(scene.set_pose),
        "sensor=tcm2 sensor.port": FakeTCM2(lambda: simulated_attitude(scene, rng_tcm2, noise_deg=0.3)),
    }
    for label, fake in fakes.items():
        fake.start()
        print(f"{fake.name:12s} {label}={fake.port}", flush=True)
    print("serving; Ctrl-C stops", file=sys.stderr, flush=True)
    try:
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
