"""The complete front end: stereo_frontend, its sequencer and the register bank."""
