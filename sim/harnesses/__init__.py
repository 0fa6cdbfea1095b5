"""MyHDL bench tops around a block (HDL consumers, recorders, real neighbours) for the benches."""
