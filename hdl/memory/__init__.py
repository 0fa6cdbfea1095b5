"""The SRAM: controller, arbiter and its masters, the subsystem, the frame buffers' handshake."""
