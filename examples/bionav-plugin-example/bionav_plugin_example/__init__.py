"""Example third-party bionav plugin."""
