"""Serial links: UART receiver and transmitter, the UART bridge to the AXI4-Lite register bus."""
