"""The Harris corner detectors, mono and stereo, their stages (Sobel, window, cornerness, pre-threshold,
NMS) and the feature list."""
