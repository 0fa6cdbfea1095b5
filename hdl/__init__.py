"""MyHDL blocks."""
