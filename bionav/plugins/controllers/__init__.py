"""bionav.plugins.controllers."""
