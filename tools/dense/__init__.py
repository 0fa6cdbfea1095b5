"""Dense disparity by census and semi-global matching (issue 28): the float reference of the hardware's
algorithm, the data sets with ground truth, the accuracy measures and the accuracy page (docs/dense.md).
The bit-true models of the blocks live in :mod:`eyestereo.tools.models` (census, sgm, median3,
dense_stereo)."""
