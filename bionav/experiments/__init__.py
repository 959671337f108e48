"""bionav.experiments."""
