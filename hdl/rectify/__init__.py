"""The rectification hardware: calculation unit, coordinate warper, fetch and interpolation, rectifier."""
