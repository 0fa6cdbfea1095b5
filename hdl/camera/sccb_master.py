"""SCCB master: writes a register table into the cameras (OV7670) at start-up and checks their IDs."""

from myhdl import Signal, always_comb, always_seq, block, concat, intbv

from eyestereo.hdl.common.checks import block_error, check_clock, check_distinct, check_int, check_reset, \
    check_signal, checked
from eyestereo.tools.models.sccb_master import END, READ, WAIT, check_rates, quarter_clocks, quarters_per_ms, rom
from eyestereo.tools.ov7670 import ID_READ, ID_WRITE, TABLE, check_table

# symbol kinds of a transaction step
_S, _B, _P = 0, 1, 2
#: the symbol of each step: a write is start, ID, sub-address, data, stop; a read is start, ID, sub-address,
#: stop, start, read ID, data from the slave, stop (SCCB has no repeated start)
_SYM_W = (_S, _B, _B, _B, _P, _P, _P, _P)
_SYM_R = (_S, _B, _B, _P, _S, _B, _B, _P)
_LAST_W, _LAST_R = 4, 7
_READ_STEP = 6  # the step whose 8 bits the slave drives
# states
_IDLE, _FETCH, _SYM, _WAIT = 0, 1, 2, 3


@block
def sccb_master(clk, rst, start, sio_c, sio_d_oe, sio_d_i, busy, done, present, *, table=TABLE,
                clk_hz=100e6, sccb_hz=100e3, cameras: int = 2):
    """Write ``table`` into every camera over SCCB after reset (and again on ``start``), then read each
    camera's PID and VER and report which answered 0x76 / 0x73.

    The cameras' buses are driven together: one SIO_C and one SIO_D drive go to every camera's bus (the
    same table for all; each camera needs its own bus because every OV7670 answers at ID 0x42/0x43), and
    each bus's SIO_D comes back on its own bit of ``sio_d_i``, so the ID reads check all cameras at once.

    The bus, per the OmniVision SCCB specification v2.2 and the OV7670 data sheet's SCCB timing: a bit is
    four *quarters* (:func:`eyestereo.tools.models.sccb_master.quarter_clocks` clocks each): SIO_C low,
    high, high, low; SIO_D changes one quarter after SIO_C fell and holds while SIO_C is high, except in
    the start (SIO_D falls while SIO_C is high) and the stop (SIO_D rises while SIO_C is high). A write is
    3 phases (ID 0x42, sub-address, data), a read 2 phases (0x42, sub-address), a stop, then 2 phases (ID
    0x43, the slave's 8 bits); the 9th bit of every phase is released (the slave's "don't care" after a
    write phase, the master's "NA" = 1 after the read data). Each entry is preceded by one idle quarter; a
    delay entry ``(0xFF, ms)`` holds the bus idle for ``ms`` milliseconds (at least). The quarter is at
    least a quarter of 1/sccb_hz and at least 650 ns, half the data sheet's SIO_C low time tLOW = 1.3 us,
    so the fastest rate is 384.6 kHz (a 400 kHz request runs there or slower).

    Bus levels (one column per quarter; ``d`` the master's SIO_D: 1 released, 0 driven low; a write of
    0x80 to register 0x12, the first bits shown; ``b7..`` the bits of 0x42 MSB first, ``x`` the released
    9th bit)::

        quarter  0   1 2 3 4   5 6 7 8   9 10 11 12 ...  37 38 39 40  ...  stop: 0 1 2 3
        sio_c    1   1 1 1 0   0 1 1 0   0  1  1  0 ...   0  1  1  0          0 1 1 1
        sio_d    1   1 0 0 0   0 0 0 0   1  1  1  1 ...   1  1  1  1          0 0 1 1
                 fetch start     b7 = 0    b6 = 1            x (released)          stop

    The pins: SIO_C is driven push-pull (``sio_c``): the master is its only driver and the OV7670 never
    stretches it (a pull-up on the board does no harm). SIO_D is open-drain: ``sio_d_oe`` high drives the
    pins low, low releases them to the pull-ups (the board top writes ``sio_d = '0' when sio_d_oe else
    'Z'`` for each camera). ``sio_d_i`` goes through two flip-flops (the slave's bits change 0.1..0.9 us
    after SIO_C falls, not with this clock); a read bit is taken at the end of SIO_C's high time.

    Ports:
        clk: the clock (``clk_hz``).
        rst: synchronous reset, active high; after it the table is written (power-up configuration).
        start: input, a pulse: write the table again (ignored while ``busy``: the run in progress writes the
            same table).
        sio_c: output, SIO_C of every camera (1 when idle).
        sio_d_oe: output, 1 = drive every camera's SIO_D low, 0 = release it.
        sio_d_i: input, ``cameras`` bits: each camera's SIO_D pin as read back.
        busy: output, high from reset or the taken ``start`` until ``done``.
        done: output, one-clock pulse at the end of a run.
        present: output, ``cameras`` bits, bit k = camera k answered PID 0x76 and VER 0x73 in the last run
            (0 after reset until the first run ends; a missing camera reads 0xFF).

    Parameters:
        table: (reg, value) pairs written in order, ``(0xFF, ms)`` a delay of 1..255 ms
            (:data:`eyestereo.tools.ov7670.TABLE`: QVGA YUV 4:2:2 for the OV7670; a user's own text file:
            :func:`eyestereo.tools.ov7670.load_table`).
        clk_hz: the clock's frequency (at least 8 x ``sccb_hz``).
        sccb_hz: highest SIO_C rate, at most 400e3 (100e3 is the SCCB's usual rate).
        cameras: number of buses read back (1..8).

    Latency: a run takes ``len(quarters(table)) * q`` clocks after reset or the quarter that takes
    ``start`` (q = clocks per quarter, :mod:`eyestereo.tools.models.sccb_master`); the OV7670 table (37
    writes, a 2 ms delay, 2 ID reads) takes 13.6 ms at 100 kHz (5453 quarters), 5.0 ms at 400 kHz (runs at
    384.6 kHz); the pins follow the state one clock later; ``done`` pulses at the end of the last idle
    quarter.

    Resources: a quarter counter, a millisecond counter, the table as a LUT ROM of 18-bit words
    (``kind``, reg, value), a handful of state registers; no block RAM, no multiplier. The OV7670 table,
    100 MHz, 100 kHz, 2 cameras (make synth's flow on this block alone): 191 LUT, 72 FF on the
    Spartan-3E; 266 LUT4, 72 FF, 178.2 MHz on the ECP5 (the slowest of nextpnr seeds 1-4).
    """
    check_clock(clk)
    check_reset(rst)
    cameras = check_int("cameras", cameras, 1, 8)
    for name, sig in (("start", start), ("sio_c", sio_c), ("sio_d_oe", sio_d_oe), ("busy", busy), ("done", done)):
        check_signal(name, sig, width=1)
    for name, sig in (("sio_d_i", sio_d_i), ("present", present)):
        check_signal(name, sig, width=cameras)
        if isinstance(sig.val, bool):
            raise block_error(f"port {name} must be a Signal(intbv(0)[{cameras}:]) (one bit per camera), "
                              f"got a Signal(bool)")
    check_distinct(dict(sio_c=sio_c, sio_d_oe=sio_d_oe, busy=busy, done=done, present=present),
                   dict(clk=clk, rst=rst, start=start, sio_d_i=sio_d_i))
    table = checked(check_table, table)
    checked(check_rates, clk_hz, sccb_hz)
    Q = quarter_clocks(clk_hz, sccb_hz)
    QPM = quarters_per_ms(clk_hz, sccb_hz)
    ROM = tuple(kind << 16 | reg << 8 | value for kind, reg, value in rom(table))
    N = len(ROM)
    ALL = (1 << cameras) - 1

    cnt = Signal(intbv(0, min=0, max=Q))
    tick = Signal(bool(0))
    state = Signal(intbv(_FETCH, min=0, max=4))
    idx = Signal(intbv(0, min=0, max=N))
    word = Signal(intbv(ROM[0])[18:])
    e_kind = Signal(intbv(0)[2:])
    e_reg, e_val = Signal(intbv(0)[8:]), Signal(intbv(0)[8:])
    step = Signal(intbv(0, min=0, max=8))
    bn = Signal(intbv(8, min=0, max=9))  # bit of the 9-bit phase, 8 (the MSB) first, 0 the released 9th
    qi = Signal(intbv(0)[2:])
    pre = Signal(intbv(0, min=0, max=QPM))
    ms = Signal(intbv(0, min=0, max=256))
    sym_w, sym_r, sym = (Signal(intbv(0, min=0, max=3)) for _ in range(3))
    last = Signal(intbv(_LAST_W, min=0, max=8))
    pbyte = Signal(intbv(0xFF)[8:])
    w9, ew9 = Signal(intbv(0x1FF)[9:]), Signal(intbv(0x1FF)[9:])
    c_lvl, d_lvl = Signal(bool(1)), Signal(bool(1))
    sync1, sync2 = Signal(intbv(ALL)[cameras:]), Signal(intbv(ALL)[cameras:])
    match = Signal(intbv(ALL)[cameras:])
    mism = Signal(intbv(0)[cameras:])
    c_r, oe_r = Signal(bool(1)), Signal(bool(0))
    busy_r, done_r = Signal(bool(1)), Signal(bool(0))
    present_r = Signal(intbv(0)[cameras:])

    @always_comb
    def rom_read():
        word.next = ROM[int(idx)]

    @always_comb
    def tick_comb():
        tick.next = cnt == Q - 1

    @always_comb
    def sym_tables():
        sym_w.next = _SYM_W[int(step)]
        sym_r.next = _SYM_R[int(step)]

    @always_comb
    def decode():
        if e_kind == READ:
            sym.next = sym_r
            last.next = _LAST_R
        else:
            sym.next = sym_w
            last.next = _LAST_W
        if step == 1:
            pbyte.next = ID_WRITE
        elif step == 2:
            pbyte.next = e_reg
        elif step == 3:
            pbyte.next = e_val
        elif step == 5:
            pbyte.next = ID_READ
        else:
            pbyte.next = 0xFF

    @always_comb
    def words():
        w9.next = concat(pbyte, True)
        ew9.next = concat(e_val, True)

    @always_comb
    def levels():
        # the level of the quarter the state stands in (the tables of tools/models/sccb_master.py)
        if state != _SYM:
            c_lvl.next = 1
            d_lvl.next = 1
        elif sym == _S:
            c_lvl.next = qi != 3
            d_lvl.next = qi == 0
        elif sym == _P:
            c_lvl.next = qi != 0
            d_lvl.next = qi >= 2
        else:
            c_lvl.next = qi == 1 or qi == 2
            d_lvl.next = w9[bn]

    @always_comb
    def mismatch():
        # the cameras whose sampled bit differs from the expected ID bit
        if ew9[bn]:
            mism.next = ~sync2 & ALL
        else:
            mism.next = sync2

    @always_seq(clk.posedge, reset=rst)
    def pins():
        # the pins from flip-flops (they can sit in the I/O blocks), one clock after the state
        c_r.next = c_lvl
        oe_r.next = not d_lvl
        sync1.next = sio_d_i
        sync2.next = sync1
        if cnt == Q - 1:
            cnt.next = 0
        else:
            cnt.next = cnt + 1

    @always_seq(clk.posedge, reset=rst)
    def fsm():
        done_r.next = 0
        if state == _IDLE:
            if start and not busy_r:
                busy_r.next = 1
            if tick and busy_r:
                state.next = _FETCH
                idx.next = 0
                match.next = ALL
        elif tick:
            if state == _FETCH:
                e_kind.next = word[18:16]
                e_reg.next = word[16:8]
                e_val.next = word[8:0]
                if word[18:16] == END:
                    state.next = _IDLE
                    busy_r.next = 0
                    done_r.next = 1
                    present_r.next = match
                else:
                    idx.next = idx + 1
                    if word[18:16] == WAIT:
                        state.next = _WAIT
                        ms.next = word[8:0]
                        pre.next = QPM - 1
                    else:
                        state.next = _SYM
                        step.next = 0
                        bn.next = 8
                        qi.next = 0
            elif state == _WAIT:
                if pre == 0:
                    if ms == 1:
                        state.next = _FETCH
                    else:
                        ms.next = ms - 1
                        pre.next = QPM - 1
                else:
                    pre.next = pre - 1
            else:
                if e_kind == READ and step == _READ_STEP and qi == 2 and bn != 0:
                    match.next = match & ~mism
                if qi != 3:
                    qi.next = qi + 1
                else:
                    qi.next = 0
                    if sym == _B and bn != 0:
                        bn.next = bn - 1
                    else:
                        bn.next = 8
                        if step == last:
                            state.next = _FETCH
                        else:
                            step.next = step + 1

    @always_comb
    def outputs():
        sio_c.next = c_r
        sio_d_oe.next = oe_r
        busy.next = busy_r
        done.next = done_r
        present.next = present_r

    return rom_read, tick_comb, sym_tables, decode, words, levels, mismatch, pins, fsm, outputs
