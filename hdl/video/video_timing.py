"""Display timing: pixel and line counters -> hsync, vsync, de and the active pixel's x, y, all registered."""

from myhdl import Signal, always, block, intbv

from eyestereo.hdl.common.checks import block_error, check_clock, check_distinct, check_reset, check_signal, checked
from eyestereo.tools.models.video_timing import mode_of


def coord_bits(n: int) -> int:
    """Bits of a coordinate 0 .. n - 1 (at least 1)."""
    return max(1, (n - 1).bit_length())


@block
def video_timing(clk, rst, hsync, vsync, de, x, y, line_start=None, frame_start=None, *, mode="640x480@60"):
    r"""The sync and blanking of a display mode (:data:`eyestereo.tools.models.video_timing.MODES`), one pixel
    per clock, for a DVI/HDMI or VGA output.

    Two counters, ``h`` (0 .. h_total - 1) and ``v`` (0 .. v_total - 1, stepping when ``h`` wraps), count
    from the leading edge of the sync pulses: sync, back porch, active, front porch, in pixels and lines,
    so that a vertical sync begins and ends with a horizontal sync's leading edge (as VESA DMT and CEA-861
    draw it). Every output is a flip-flop loaded from the counters at the same edge, so all of them describe
    the same counter state; the first edge with ``rst`` low shows state 0, the leading edge of both syncs.
    One line, in clocks after the outputs show ``h`` = 0 (640x480: sync 96, back porch 48, active 640, front
    porch 16; a negative hsync drawn)::

        h            0 .. h_sync-1 | h_sync .. h_start-1 | h_start .. h_start+h_active-1 | .. h_total-1 | 0
        clk          _|~|_|~|_ ... _|~|_ ... _|~|_|~|_|~|_ ... _|~|_|~|_ ... _|~|_ ... _|~|_|~|_|~|_ ...
        hsync        \_____________/~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~\____
        line_start   /~~\______________________________________________________________________/~~\__
        de           ____________________________/~~~~~~~~~~~~~~~~~~~~~~~~~~~~~\____________________
        x            0 ...                     0 | 0   1   2  ...   h_active-1 | 0 ...

    Frames are the same in lines: vertical sync (``v`` 0 .. v_sync - 1), back porch, active lines, front
    porch; ``vsync`` changes together with ``hsync``'s leading edge, ``y`` counts the active lines.
    ``line_start`` pulses on lines that have active pixels only; ``frame_start`` pulses with state 0 (the
    vertical sync's leading edge).

    Fetching pixels: a consumer that reads its pixel from ``x``, ``y`` and registers it once (a block-RAM
    read, or a register after a look-up) presents it one clock after ``de`` marks it: it must delay
    ``hsync``, ``vsync`` and ``de`` by the same one clock (one flip-flop each) before the TMDS encoders, or
    read ahead. Each register stage more is one clock more. A line fetched into a line buffer before it is
    shown can start at ``line_start``, ``h_sync + h_back`` clocks (640x480: 144 = 5.76 us at 25 MHz) before
    the line's first pixel; a frame's first line at ``frame_start``, ``(v_sync + v_back) * h_total + h_sync
    + h_back`` clocks before its first pixel (640x480: 28144).

    640x480 at 60 Hz from 25.0 MHz instead of 25.175 MHz: 59.52 Hz frames, which monitors take as the
    60 Hz mode (the model's module docstring says more).

    Ports:
        clk: pixel clock.
        rst: the library's synchronous active-high reset; outputs inactive (syncs at their idle level, ``de``
            and the pulses low, x = y = 0) while it is high.
        hsync, vsync: outputs, Signal(bool): the syncs at the pin's levels (the mode's polarities applied).
        de: output, Signal(bool): an active pixel.
        x, y: outputs, ``Signal(intbv)`` of exactly the bits of h_active - 1 and v_active - 1 (640x480: 10, 9):
            the active pixel's column and line while ``de``, 0 outside.
        line_start: output, Signal(bool), optional: one clock at the horizontal sync's leading edge of an
            active line.
        frame_start: output, Signal(bool), optional: one clock at the vertical sync's leading edge.

    Parameters:
        mode: a name of :data:`~eyestereo.tools.models.video_timing.MODES` ("640x480@60", "sim-64x48",
            "sim-32x24") or a :class:`~eyestereo.tools.models.video_timing.VideoMode`.

    Latency: 1 clock from a counter state to the outputs (all outputs alike); x, y and de together.

    Resources: two counters (640x480: 10 + 10 bits), comparators with constants, the output flip-flops; 640x480
    (make synth's flow, Yosys xc3se): 55 LUT, 44 FF; nextpnr-ecp5 190.2 MHz (the slowest of seeds 1-4; goal 25).
    """
    check_clock(clk)
    check_reset(rst)
    m = checked(mode_of, mode)
    # the pulses are optional: a user without them gets internal flip-flops that synthesis removes
    line_start = Signal(bool(0)) if line_start is None else line_start
    frame_start = Signal(bool(0)) if frame_start is None else frame_start
    for name, sig in (("hsync", hsync), ("vsync", vsync), ("de", de), ("line_start", line_start),
                      ("frame_start", frame_start)):
        check_signal(name, sig, width=1)
    for name, sig, n in (("x", x, m.h_active), ("y", y, m.v_active)):
        check_signal(name, sig)
        if isinstance(sig.val, bool) or len(sig) != coord_bits(n) or (sig.min is not None and sig.min < 0):
            raise block_error(f"port {name} must be an unsigned Signal(intbv(0)[{coord_bits(n)}:]) for the "
                              f"{n} {'columns' if name == 'x' else 'lines'} of mode {m.name}, got "
                              f"{'a Signal(bool)' if isinstance(sig.val, bool) else f'{len(sig)} bits'}")
    check_distinct(dict(hsync=hsync, vsync=vsync, de=de, x=x, y=y, line_start=line_start, frame_start=frame_start),
                   dict(clk=clk, rst=rst))

    H_LAST, V_LAST = m.h_total - 1, m.v_total - 1
    H_SYNC, V_SYNC = m.h_sync, m.v_sync
    H0, H1 = m.h_start, m.h_start + m.h_active
    V0, V1 = m.v_start, m.v_start + m.v_active
    H_ON, H_OFF = bool(m.h_pol), not m.h_pol
    V_ON, V_OFF = bool(m.v_pol), not m.v_pol
    h = Signal(intbv(0, min=0, max=m.h_total))
    v = Signal(intbv(0, min=0, max=m.v_total))

    @always(clk.posedge)
    def count():
        if rst:
            h.next = 0
            v.next = 0
        elif h == H_LAST:
            h.next = 0
            if v == V_LAST:
                v.next = 0
            else:
                v.next = v + 1
        else:
            h.next = h + 1

    # Written out instead of always_seq: the syncs' idle level is the mode's, not the port's initial value.
    @always(clk.posedge)
    def outputs():
        if rst:
            hsync.next = H_OFF
            vsync.next = V_OFF
            de.next = 0
            x.next = 0
            y.next = 0
            line_start.next = 0
            frame_start.next = 0
        else:
            hsync.next = H_ON if h < H_SYNC else H_OFF
            vsync.next = V_ON if v < V_SYNC else V_OFF
            line_start.next = h == 0 and v >= V0 and v < V1
            frame_start.next = h == 0 and v == 0
            if h >= H0 and h < H1 and v >= V0 and v < V1:
                de.next = 1
                x.next = h - H0
                y.next = v - V0
            else:
                de.next = 0
                x.next = 0
                y.next = 0

    return count, outputs
