"""Video output: display timing, TMDS (DVI/HDMI) encoding, the overlay of the board's monitor picture."""
