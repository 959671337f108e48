"""bionav.report."""
