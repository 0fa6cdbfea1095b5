"""Generic stream blocks: line delay, convolution, the protocol checker, the clock-domain crossings
(async_fifo, stream_cdc, word_cdc)."""
