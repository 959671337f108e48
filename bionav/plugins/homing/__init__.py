"""bionav.plugins.homing."""
