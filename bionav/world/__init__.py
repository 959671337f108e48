"""bionav.world."""
