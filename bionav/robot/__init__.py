"""The simulated cleaning robot of thesis chapter 7.

Differential-drive kinematics (:mod:`.kinematics`), the controller protocol
(:mod:`.controller`), the meander state machine (:mod:`.meander`),
triangulation against the previous lane (:mod:`.triangulation`), coverage
analysis (:mod:`.coverage`), lane geometry (:mod:`.lanes`), the simulator
(:mod:`.simulator`, :mod:`.floorplan`, :mod:`.worldview`), home vectors from
true geometry (:mod:`.oracle`) and logging/replay (:mod:`.recording`,
:mod:`.replay`).
"""
