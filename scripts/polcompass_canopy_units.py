"""What limits the compass under canopy: each unit's part in the canopy sessions (issue 41, a diagnostic).

For every canopy session of ``--recordings`` (``recordings.path``; the condition read from the path), prints one
JSON object per unit: its median degree of polarization and usable fraction under canopy, against the same in the
daylight sessions, and the MAE of ``decoder=sky_fit`` (uncalibrated, the sun at each sample's time) under both
named rules with that unit left out, beside the MAE with every unit. Nothing is learned or chosen from it: it is a
look at which units see open sky, not a tuning. Usage::

    python scripts/polcompass_canopy_units.py --recordings ../shared/data/celestial-compass
"""

from __future__ import annotations

import argparse
import json
from dataclasses import replace

import numpy as np


def _without_unit(data, k: int):
    valid = data.valid.copy()
    valid[:, k] = False
    ev = data.evectors
    ok = None if ev.pol_op_valid is None else ev.pol_op_valid.copy()
    if ok is not None:
        ok[:, k] = False
    return replace(data, valid=valid, evectors=replace(ev, pol_op_valid=ok))


def _mae(decoder, data) -> dict:
    from bionav.polcompass.references import reference_errors
    from bionav.polcompass.sessions import decode_session

    heading = decode_session(decoder, data)[0]
    return {rule: float(np.degrees(np.mean(np.abs(reference_errors(heading, data, ref)[0]))))
            for rule, ref in (("logged", "session"), ("stitched", "stitched"))}


def _median_degree(datas, k: int):
    d = [x.evectors.degree[x.valid[:, k], k] for x in datas]
    d = np.concatenate(d) if d else np.zeros(0)
    return float(np.median(d)) if d.size else None


def main(argv=None) -> int:
    from bionav.plugins.decoders.sky_fit import SkyFit, SkyFitConfig
    from bionav.polcompass.recordings_config import recordings_config
    from bionav.polcompass.sessions import prepared_sessions

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--recordings", required=True, help="the celestial-compass folder (tod_data/, canopy_data/)")
    args = parser.parse_args(argv)
    prepared, _bad = prepared_sessions(recordings_config({"path": args.recordings}))
    canopy = [d for d in prepared if d.period == "canopy"]
    daylight = [d for d in prepared if d.period == "tod_daylight"]
    decoder = SkyFit(SkyFitConfig())
    for data in canopy:
        every = _mae(decoder, data)
        print(json.dumps({"session": data.session.name, "unit": "all", "mae_deg": every}))
        for k in range(data.valid.shape[1]):
            if k in data.excluded:
                continue
            print(json.dumps({
                "session": data.session.name, "unit": k,
                "usable_fraction": float(np.mean(data.valid[:, k])),
                "median_degree": _median_degree([data], k),
                "median_degree_daylight": _median_degree(daylight, k),
                "mae_deg_without": _mae(decoder, _without_unit(data, k)),
            }))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
