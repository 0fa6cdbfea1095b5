"""Benchmark and report scripts that write the measured pages in ``docs/``."""
