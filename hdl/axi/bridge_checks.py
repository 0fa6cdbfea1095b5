"""The port and frame checks both AXI4-Stream video bridges make (image stream on one side, AXI on the other)."""

from eyestereo.hdl.common.checks import check_axis, check_clock, check_distinct, check_frame, check_reset, \
    check_signal, check_stream


def check_bridge(clk, rst, image: tuple, axis: tuple, flag: tuple, *, outputs: tuple, width, height) -> tuple:
    """Check a bridge's ports and frame size; returns ``(data_width, width, height)``.

    ``image``, ``axis`` and ``flag`` are ``(name, port)`` pairs: the image stream (its data width sets
    the AXI stream's), the AXI stream and the 1-bit status output. ``outputs`` names the two of them the
    block drives; they must be distinct from every other port.
    """
    check_clock(clk)
    check_reset(rst)
    check_stream(*image)
    dw = image[1].data_width
    check_axis(*axis, data_width=dw)
    check_signal(*flag, width=1)
    ports = dict((image, axis, flag))
    driven = {name: ports[name] for name in outputs}
    check_distinct(driven, dict(clk=clk, rst=rst, **{n: p for n, p in ports.items() if n not in driven}))
    return (dw, *check_frame(width, height))
