"""World builders: each returns a :class:`~bionav.world.worlds.common.World` generated from a seed.

* :func:`~bionav.world.worlds.lab.build_lab` / ``build_lab_variant`` -- Vardy's
  laboratory (*original* and its seven variants).
* :func:`~bionav.world.worlds.hall.build_hall` -- the dim hall (*hall1*, *hall2*).
* :func:`~bionav.world.worlds.living.build_living_room` (*moeller1*),
  :func:`~bionav.world.worlds.living.build_living_kitchen` (*roeben1*).
* :func:`~bionav.world.worlds.outdoor.build_campus` -- outdoors (*uni*), with
  pluggable bands, albedos and sky.
* :func:`~bionav.world.worlds.apartment.build_apartment` -- the cleaning-robot room.
* :func:`~bionav.world.worlds.garden.garden_scene`,
  :func:`~bionav.world.worlds.garden.backyard_scene` -- the five-band outdoor
  scenes of thesis chapter 6 (:class:`~bionav.world.worlds.garden.OutdoorScene`,
  rendered with spectral daylight; not a :class:`World`).
"""
