"""bionav.plugins.sensors."""
