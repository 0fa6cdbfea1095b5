"""Measurements written to docs/: benchmarks, the suite's time, vhdl_diff."""
