"""Bridges between the image stream and AXI4-Stream video."""
