"""Decoding speed of the POL-OP decoders: ``python -m bionav.bench.decoders``."""
