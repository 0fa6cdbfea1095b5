"""Camera to image stream: the OV6630's VSYNC/HREF/8-bit bus into 16-bit YUV words, whole frames only."""

from myhdl import Signal, always, always_comb, always_seq, block, concat, intbv

from eyestereo.hdl.interfaces.camera_bus import CameraBus
from eyestereo.hdl.common.checks import block_error, check_choice, check_int, check_reset, check_stream
from eyestereo.tools.constants import FRAME_HEIGHT, FRAME_MAX, FRAME_MIN, FRAME_WIDTH
from eyestereo.tools.camera import ORDERS, WORD
from eyestereo.tools.models.camera_stream import POSITIONS


def check_camera(name: str, cam, data_width: int = 8) -> None:
    """A :class:`~eyestereo.hdl.interfaces.camera_bus.CameraBus` port with ``data_width`` data bits."""
    if not isinstance(cam, CameraBus):
        raise block_error(f"port {name} must be a CameraBus (pclk, vsync, href, data), got "
                         f"{'None' if cam is None else type(cam).__name__}")
    if cam.data_width != data_width:
        raise block_error(f"port {name} must have {data_width} data bits, got a CameraBus of {cam.data_width}")


def check_camera_params(width, height, order, vsync_active, href_active) -> tuple:
    """The camera parameters checked (for camera_stream and the blocks that wrap it), as plain values."""
    width = check_int("width", width, FRAME_MIN, FRAME_MAX)
    if width % 2:
        raise block_error(f"parameter width={width} must be even: YUV 4:2:2 pixels come in pairs")
    height = check_int("height", height, 1, FRAME_MAX)
    order = check_choice("order", order, ORDERS)
    vsync_active = check_choice("vsync_active", vsync_active, (0, 1))
    href_active = check_choice("href_active", href_active, (0, 1))
    return width, height, order, vsync_active, href_active


@block
def camera_stream(cam, rst, source, luma=None, *, width: int = FRAME_WIDTH, height: int = FRAME_HEIGHT,
                  order: str = "YUYV", vsync_active: int = 1, href_active: int = 1):
    """Receive a camera's 8-bit YUV 4:2:2 bus and emit one 16-bit word per pixel as an image stream.

    Runs in the camera's clock domain (``cam.pclk``). Every input is registered once at the rising edge
    (the flip-flops can sit in the I/O blocks). A frame begins with VSYNC; each line is ``2 * width``
    bytes under HREF; each pixel pair's four bytes give two words, Y in bits 7..0 and the chroma in
    15..8, U for the even pixel and V for the odd one (:data:`eyestereo.tools.camera.WORD`), whatever the
    bus's byte order. The line and byte counters check the geometry, so only whole frames pass:

    * a frame whose VSYNC was not seen (the block left reset, or the camera was switched on, after it)
      is ignored: no word of it comes out;
    * a line shorter or longer than ``2 * width`` bytes, or a VSYNC before the frame's last line, aborts
      the frame: if any word of it has come out, a reset token (``eof`` without ``eol``) follows, so no
      consumer takes a broken frame for a good one; then the block waits for the next VSYNC;
    * ``eol`` and ``eof`` leave only once HREF has dropped at the right byte: a frame that ends with
      ``eof`` had every line exactly right;
    * a reset token's data bits are unspecified (they keep the last word's: one mux level less);
    * lines after the frame's last one are ignored until the next VSYNC.

    Ports:
        cam: :class:`~eyestereo.hdl.interfaces.camera_bus.CameraBus` (``cam_pclk`` is this block's clock).
        rst: synchronous reset in the camera clock domain, active high: the block forgets the frame in
            progress (without a token: a FIFO behind it is reset with it) and waits for a VSYNC.
        source: :class:`~eyestereo.hdl.interfaces.stream.ImageStream` of 16-bit camera words (no back-pressure).
        luma: optional ImageStream of 8 bits: the same beats with Y only (for a grey-level path).

    Parameters:
        width, height: active pixels per line (even, 2..4096) and lines per frame (1..4096).
        order: byte order on the bus: ``YUYV`` (the thesis's Fig. 7.3), ``YVYU``, ``UYVY``, ``VYUY``.
        vsync_active, href_active: active level (1 or 0) of VSYNC and HREF.

    Latency: 1 PCLK: the even pixel's word is in the output register from the edge after the one that
    samples its pair's 4th byte; the odd pixel's word one edge later (with the next byte, or with the
    first blanking sample for a line's last pair, which is when its ``eol`` is known). A pair's two words
    come in consecutive PCLKs, a pair every 4 PCLKs (two words every 4 on average; found by the formal
    proof's cover, docs/formal.md).

    Timing (a 4-pixel line, YUYV; a column per rising edge: the bus as that edge samples it, the output
    as that edge loads it; ``A``/``B``: the words of pixels 0/1, ``C``/``D`` of pixels 2/3)::

        edge      0    1    2    3    4    5    6    7    8    9    10
        href      #    #    #    #    #    #    #    #    _    _    _
        data      Y0   U0   Y1   V0   Y2   U2   Y3   V2   .    .    .
        valid     _    _    _    _    #    #    _    _    #    #    _
        eol       .    .    .    .    _    _    .    .    _    #    .
        source    .    .    .    .    A    B    .    .    C    D    .

    Resources: two counters (bytes per line, lines per frame), three byte registers, a 16-bit output
    register and a held word; no block RAM, no multiplier.
    """
    check_camera("cam", cam)
    check_reset(rst)
    check_stream("source", source, width=WORD.width)
    if luma is not None:
        check_stream("luma", luma, width=8)
    width, height, order, vsync_active, href_active = check_camera_params(width, height, order, vsync_active,
                                                                          href_active)

    W2 = 2 * width
    LAST = height - 1
    VS_ON = bool(vsync_active)
    HR_ON = bool(href_active)

    pclk = cam.pclk
    vs_r, hr_r = Signal(bool(0)), Signal(bool(0))
    d_r = Signal(intbv(0)[8:])
    b0, b1, b2 = (Signal(intbv(0)[8:]) for _ in range(3))
    pend = Signal(intbv(0)[16:])
    n = Signal(intbv(0, min=0, max=W2 + 1))  # bytes of the current line so far
    y = Signal(intbv(0, min=0, max=height))  # complete lines of the current frame
    armed = Signal(bool(0))  # a frame began with VSYNC and is neither complete nor aborted
    started = Signal(bool(0))  # a word of the current frame has come out
    phase = Signal(intbv(0)[2:])

    # The output register (VHDL-93 cannot read the output ports for the luma copy).
    o_data = Signal(intbv(0)[16:])
    o_valid, o_eol, o_eof = Signal(bool(0)), Signal(bool(0)), Signal(bool(0))

    src = [b0, b1, b2, d_r]
    iy0, iu, iy1, iv = POSITIONS[order]
    y0s, us, y1s, vs_ = src[iy0], src[iu], src[iy1], src[iv]

    @always(pclk.posedge)
    def inputs():
        # Plain sampling registers, no reset: they can be the I/O blocks' input flip-flops.
        vs_r.next = cam.vsync == VS_ON
        hr_r.next = cam.href == HR_ON
        d_r.next = cam.data

    @always_comb
    def byte_phase():
        phase.next = n[2:]

    # The frame in progress breaks: a VSYNC before its last line, a byte beyond the line's 2 * width, or
    # HREF dropped before it.
    abort = Signal(bool(0))

    @always_comb
    def check():
        abort.next = False
        if armed:
            if vs_r:
                abort.next = y != 0 or n != 0
            elif hr_r:
                abort.next = n == W2
            else:
                abort.next = n != 0 and n != W2

    @always_seq(pclk.posedge, reset=rst)
    def fsm():
        o_valid.next = False
        o_eol.next = False
        o_eof.next = False
        if abort and started:
            # the reset token: words of the broken frame have come out
            o_valid.next = True
            o_eof.next = True
        if vs_r:
            armed.next = True
            started.next = False
            y.next = 0
            n.next = 0
        elif abort:
            armed.next = False
            started.next = False
            n.next = 0
        elif hr_r:
            if armed:
                if phase == 0:
                    b0.next = d_r
                    if n != 0:
                        o_valid.next = True
                        o_data.next = pend
                elif phase == 1:
                    b1.next = d_r
                elif phase == 2:
                    b2.next = d_r
                else:
                    o_valid.next = True
                    o_data.next = concat(us, y0s)
                    pend.next = concat(vs_, y1s)
                    started.next = True
                n.next = n + 1
        elif armed and n != 0:
            # HREF dropped after the line's last byte (n == W2: any other count aborts)
            o_valid.next = True
            o_eol.next = True
            o_data.next = pend
            if y == LAST:
                o_eof.next = True
                armed.next = False
                started.next = False
                y.next = 0
            else:
                y.next = y + 1
            n.next = 0

    @always_comb
    def out():
        source.data.next = o_data
        source.valid.next = o_valid
        source.eol.next = o_eol
        source.eof.next = o_eof

    insts = [inputs, byte_phase, check, fsm, out]
    if luma is not None:
        @always_comb
        def luma_out():
            luma.data.next = o_data[8:]
            luma.valid.next = o_valid
            luma.eol.next = o_eol
            luma.eof.next = o_eof

        insts.append(luma_out)
    return insts
