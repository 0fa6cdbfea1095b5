"""Bit-true models, fixed point and software tools (numpy/OpenCV only)."""
