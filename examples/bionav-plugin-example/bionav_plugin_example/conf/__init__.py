"""Config folders of the example plugin (found through the ``bionav.configs`` entry point)."""
