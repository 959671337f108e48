"""Fake serial devices on pseudo-terminals, for tests and demos without hardware.

``python -m bionav.plugins.sensors.fakes`` serves a simulated DLP-IO8-G
(polarized-light compass), PTU-46 and TCM2 sharing one simulated sky and
prints their ports, so the real drivers can be run against them from another
terminal, e.g.::

    python -m bionav experiment=pol_compass sensor=polcompass_serial sensor.port=/dev/pts/5 \\
        pantilt=ptu46 pantilt.port=/dev/pts/6

(``experiment.fake_devices=true`` does the same inside one run.) The fakes:
:mod:`~bionav.plugins.sensors.fakes.dlpio8`, :mod:`~bionav.plugins.sensors.fakes.ptu46`,
:mod:`~bionav.plugins.sensors.fakes.tcm2` and :mod:`~bionav.plugins.sensors.fakes.spectral5`
(the five-channel board; ``--scene spectral``).
"""
