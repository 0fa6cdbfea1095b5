"""The bench library: runners, the base bench, stream drivers, bus and memory models, traffic agents."""
