"""The complete front end: stereo_frontend, its sequencer, the register bank and its frame-handshake wiring."""
