"""bionav.plugins."""
