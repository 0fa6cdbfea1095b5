"""The host side of a board: the UART bridge's protocol, a serial transport for the host driver, the board's
registers (eyestereo board ...)."""
