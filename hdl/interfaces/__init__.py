"""Port bundles: the image stream, the queue read port, the fetch port, the coordinate pair, the SRAM
buses, the camera bus, AXI4-Lite and AXI4-Stream; with their checks and timing diagrams."""
