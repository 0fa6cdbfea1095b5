"""The Rectification Toolbox: calibration, synthetic rig, maps, polynomial regression, float-to-fixed
conversion, warping, LUT export, VHDL package and the whole run (thesis chapters 3, 4 and Appendix A)."""
