"""bionav.testing."""
