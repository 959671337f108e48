"""A stand-in for the experiment runner's RunContext (only what the spectral experiments use)."""

from pathlib import Path

import numpy as np


class FakeLog:
    def __init__(self):
        self.messages = []

    def write(self, topic, message, *, schema_name, schema=None, log_time_ns=None):
        self.messages.append((topic, message, schema_name))


class FakeContext:
    def __init__(self, tmp_path, seed=0):
        self.dir = Path(tmp_path)
        self.plots = self.dir / "plots"
        self.plots.mkdir(exist_ok=True)
        self.rng = np.random.default_rng(seed)
        self.log = FakeLog()

    def progress(self, iterable, *, desc="", total=None):
        return iterable
