"""``python -m bionav.experiments.cleaning_replay RUN_DIR_OR_MCAP [--run K ...]``: replay logged cleaning runs.

Rebuilds controller, homing method, layout and (for images that were not
logged) the camera from the config attached to ``run.mcap``, feeds every
logged observation back through the controller and checks that it emits the
logged commands exactly. Exit status 0 when every run matches, 2 on the first
mismatch (with a message saying where).
"""
