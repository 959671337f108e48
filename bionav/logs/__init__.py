"""bionav.logs."""
