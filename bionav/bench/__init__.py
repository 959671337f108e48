"""Benchmarks of bionav's homing methods (``python -m bionav.bench --help``)."""
