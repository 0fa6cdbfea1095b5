"""The camera path: camera bus to image stream, and through the async FIFO into the system clock."""
