"""``python -m bionav.bench.sweep``: the same 4-job sweep with the basic and the joblib launcher.

Each job is a grid-homing run (one worker thread per job, so the launcher is
what parallelises); the sweep directories go to a temporary folder. Prints
wall times and the speed-up. Needs ``pip install bionav[parallel]``.
"""
