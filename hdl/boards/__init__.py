"""Board-level designs: a board's top around the stereo front end (clocks, pins, cameras, memory, monitor, host link)
and the vendor primitives it needs (ECP5 PLL and DDR outputs, with simulation models)."""
