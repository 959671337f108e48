"""bionav.plugins.signatures."""
