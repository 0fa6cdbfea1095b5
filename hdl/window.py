"""Window machinery shared by the filters (thesis 6.2.1): column taps, shift-and-add sums, border control.

A filter is assembled from three parts:

* :func:`column_taps` -- N-1 chained :func:`~eyestereo.hdl.line_delay.line_delay` blocks and alignment
  registers: N pixels of one image column (rows y-r .. y+r), all valid in the same clock.
* arithmetic on the taps, by :func:`shift_add` (constant coefficients as shifts and adds) and plain
  registers, free-running: it needs no enable, because the control path carries the timing.
* :func:`window_control` -- the control unit of "border treatment, option 3": the output frame has the
  input's size and valid/eol/eof pattern; output pixel (x, y) is the response of the window centred on
  input pixel (x, y). The output runs ``r * width + r`` pixels behind the input; after the input frame's
  last pixel the control unit emits the missing pixels by itself, one per clock, so no further input is
  needed. Those pixels, and all others whose window leaves the image, carry unspecified data.

These are helpers, not stream blocks: they are instantiated inside blocks such as
:func:`~eyestereo.hdl.convolve.convolve` and :func:`~eyestereo.hdl.sobel.sobel`.
"""

from myhdl import Signal, always, always_comb, always_seq, block, intbv

from eyestereo.hdl.line_delay import line_delay
from eyestereo.hdl.stream import ImageStream


def _copy(sig):
    return Signal(intbv(0, min=sig.min, max=sig.max)) if sig.min is not None else Signal(intbv(0)[len(sig):])


@block
def delay(clk, din, dout, *, clocks: int):
    """``dout`` = ``din`` delayed by ``clocks`` (>= 1) free-running registers (no reset, no enable)."""
    if clocks < 1:
        raise ValueError(f"delay needs clocks >= 1, got {clocks}")
    stages = [_copy(din) for _ in range(clocks - 1)] + [dout]
    insts = []
    src = din
    for dst in stages:
        insts.append(dreg(clk, src, dst))
        src = dst
    return insts


@block
def dreg(clk, d, q):
    @always(clk.posedge)
    def reg():
        q.next = d

    return reg


@block
def en_reg(clk, en, d, q):
    """q takes d on the clock edges where en is high (a register with enable, no reset)."""

    @always(clk.posedge)
    def reg():
        if en:
            q.next = d

    return reg


@block
def column_taps(clk, rst, sink, taps, tap_valid, *, width: int, height: int):
    """N pixels of one column, rows y-r (``taps[0]``) .. y+r (``taps[-1]``), aligned to one clock.

    ``taps[-1]`` is the newest pixel (the sink's), ``taps[0]`` the one N-1 lines earlier. The taps and
    ``tap_valid`` (a pixel beat, not a reset token) are registered N-1 clocks after the sink beat.
    """
    n = len(taps)
    if n < 2:
        raise ValueError("column_taps needs at least 2 taps")
    dw = len(sink.data)
    insts = []
    streams = [sink]
    for _ in range(n - 1):
        s = ImageStream(dw)
        insts.append(line_delay(clk, rst, streams[-1], s, width=width, height=height))
        streams.append(s)
    # streams[k] is k lines old and k clocks late; bring them all to n-1 clocks.
    for k, s in enumerate(streams):
        tap = taps[n - 1 - k]
        if k == n - 1:
            insts.append(assign(s.data, tap))
        else:
            insts.append(delay(clk, s.data, tap, clocks=n - 1 - k))
    pix = Signal(bool(0))

    @always_comb
    def decode():
        pix.next = sink.valid and (sink.eol or not sink.eof)

    insts.append(decode)
    insts.append(delay(clk, pix, tap_valid, clocks=n - 1))
    return insts


@block
def assign(a, b):
    @always_comb
    def comb():
        b.next = a

    return comb


def csd(k: int) -> list[tuple[int, int]]:
    """Canonical signed digits of an integer: [(sign, shift), ...] with k = sum(sign << shift)."""
    digits = []
    shift = 0
    while k != 0:
        if k & 1:
            d = 2 - (k & 3)  # +1 or -1, chosen so the next bit is 0
            digits.append((d, shift))
            k -= d
        k >>= 1
        shift += 1
    return digits


def term_range(sig, coeff: int) -> tuple[int, int]:
    lo, hi = _sig_range(sig)
    a, b = lo * coeff, hi * coeff
    return min(a, b), max(a, b)


def _sig_range(sig) -> tuple[int, int]:
    if sig.min is not None:
        return sig.min, sig.max - 1
    return 0, (1 << len(sig)) - 1


def _sig(lo: int, hi: int):
    if lo >= 0:
        return Signal(intbv(0, min=0, max=max(hi, 0) + 1))
    return Signal(intbv(0, min=lo, max=max(hi, 0) + 1))


@block
def shift_add(terms, out):
    """Combinational ``out = sum(coeff * sig)`` for constant integer coefficients, by shifts and adds.

    Each coefficient is split into canonical signed digits; the shifted terms are summed by a balanced
    tree of adders whose widths follow the exact value range of each node, so nothing can overflow.
    ``out`` must hold the whole range (checked at elaboration).
    """
    leaves = []  # (signal, lo, hi)
    insts = []
    for sig, coeff in terms:
        for sign, shift in csd(int(coeff)):
            lo, hi = term_range(sig, sign << shift)
            lf = _sig(lo, hi)
            insts.append(leaf(sig, lf, sign, shift))
            leaves.append((lf, lo, hi))
    if not leaves:
        leaves.append((_sig(0, 0), 0, 0))
    while len(leaves) > 1:
        nxt = []
        for i in range(0, len(leaves) - 1, 2):
            (a, alo, ahi), (b, blo, bhi) = leaves[i], leaves[i + 1]
            s = _sig(alo + blo, ahi + bhi)
            insts.append(adder(a, b, s))
            nxt.append((s, alo + blo, ahi + bhi))
        if len(leaves) % 2:
            nxt.append(leaves[-1])
        leaves = nxt
    root = leaves[0][0]
    # The tree's node ranges are loose (a CSD digit pair like 4x - x spans more than 3x does); the
    # output only has to hold the exact range of the sum.
    lo = sum(term_range(sig, int(c))[0] for sig, c in terms)
    hi = sum(term_range(sig, int(c))[1] for sig, c in terms)
    olo, ohi = _sig_range(out)
    if lo < olo or hi > ohi:
        raise ValueError(f"shift_add output range [{olo}, {ohi}] cannot hold the sum's [{lo}, {hi}]")
    insts.append(assign(root, out))
    return insts


@block
def leaf(sig, out, sign: int, shift: int):
    if sign > 0:
        @always_comb
        def pos():
            out.next = sig << shift

        return pos

    # VHDL has no unary minus on unsigned, and a shift keeps its operand's width: shift into a signed
    # signal wide enough for the shifted value first, then negate.
    lo, hi = _sig_range(sig)
    mag = max(abs(lo), abs(hi)) << shift
    wide = Signal(intbv(0, min=-mag - 1, max=mag + 1))

    @always_comb
    def widen():
        wide.next = sig << shift

    @always_comb
    def neg():
        out.next = -wide

    return widen, neg


@block
def adder(a, b, s):
    @always_comb
    def add():
        s.next = a + b

    return add


@block
def window_control(clk, rst, sink, source, *, width: int, height: int, radius: int, latency: int):
    """Control unit for border treatment option 3: drives ``source.valid/eol/eof``.

    The data path must put output pixel (x, y) on ``source.data`` exactly ``latency`` clocks after the
    sink beat of input pixel (x + r, y + r) (r = ``radius``). This unit emits that pixel's flags at the
    same time, counts the output raster, emits the last ``r * width + r`` pixels of each frame on its own
    after the input frame's last pixel (one per clock), and forwards a reset token after ``latency``
    clocks, clearing its counters.

    Why no collision: a frame's own first output needs ``r * width + r + 1`` of its pixels, so it comes
    after the previous frame's self-emitted tail even when frames arrive back to back.
    """
    lead = radius * width + radius
    if lead >= width * height:
        raise ValueError(f"a {2 * radius + 1}x{2 * radius + 1} window needs a frame larger than {width}x{height}")
    if latency < 1:
        raise ValueError("window_control latency must be >= 1")
    skip = Signal(intbv(lead, min=0, max=lead + 1))
    tail = Signal(intbv(0, min=0, max=lead + 1))
    ox = Signal(intbv(0, min=0, max=width))
    oy = Signal(intbv(0, min=0, max=height))
    v0, l0, f0 = Signal(bool(0)), Signal(bool(0)), Signal(bool(0))

    @always_seq(clk.posedge, reset=rst)
    def count():
        emit = False
        v0.next = False
        l0.next = False
        f0.next = False
        if sink.valid and sink.eof and not sink.eol:
            # Reset token: abandon the frame in progress and pass the token on.
            skip.next = lead
            tail.next = 0
            ox.next = 0
            oy.next = 0
            v0.next = True
            f0.next = True
        else:
            if sink.valid:
                if skip == 0:
                    emit = True
                if sink.eof:
                    skip.next = lead
                    tail.next = lead
                elif skip != 0:
                    skip.next = skip - 1
            if tail != 0:
                emit = True
                if not (sink.valid and sink.eof):
                    tail.next = tail - 1
            if emit:
                v0.next = True
                if ox == width - 1:
                    l0.next = True
                    ox.next = 0
                    if oy == height - 1:
                        f0.next = True
                        oy.next = 0
                    else:
                        oy.next = oy + 1
                else:
                    ox.next = ox + 1

    insts = [count]
    if latency == 1:
        insts += [assign(v0, source.valid), assign(l0, source.eol), assign(f0, source.eof)]
    else:
        for a, b in ((v0, source.valid), (l0, source.eol), (f0, source.eof)):
            insts.append(delay_rst(clk, rst, a, b, clocks=latency - 1))
    return insts


@block
def delay_rst(clk, rst, din, dout, *, clocks: int):
    """Like :func:`delay` for 1-bit control, with a synchronous reset so no stale flag survives ``rst``."""
    stages = [Signal(bool(0)) for _ in range(clocks - 1)] + [dout]
    insts = []
    src = din
    for dst in stages:
        insts.append(dreg_rst(clk, rst, src, dst))
        src = dst
    return insts


@block
def dreg_rst(clk, rst, d, q):
    @always_seq(clk.posedge, reset=rst)
    def reg():
        q.next = d

    return reg
