"""bionav.stats."""
