"""Tables and statistics across runs and sweeps."""
