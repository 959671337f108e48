"""Decoder plugins (``decoder=<name>``): solar azimuth from a POL-OP array's e-vectors."""
