"""cocotb benches and the GHDL runner helper."""
