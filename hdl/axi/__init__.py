"""AXI: the AXI4-Stream video bridges, and the AXI4-Lite interconnect (an arbiter of two masters, an address split)."""
