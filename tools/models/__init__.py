"""Bit-true numpy models, one per hardware block, each named after its block in ``eyestereo.hdl``."""
