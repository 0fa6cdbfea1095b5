"""The EDA flow: the block catalogue, conversion, synthesis, timing estimates, netlists, FuseSoC cores,
the WaveDrom pictures. Imports the blocks; no block imports it."""
