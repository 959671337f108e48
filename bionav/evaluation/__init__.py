"""bionav.evaluation."""
