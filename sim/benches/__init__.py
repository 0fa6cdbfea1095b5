"""cocotb benches, one ``tb_<block>.py`` per block or scenario; a bench imports the library, never another bench."""
