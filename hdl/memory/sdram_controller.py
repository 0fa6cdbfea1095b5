"""SDR SDRAM controller: a 16-bit SDRAM's pins on one side, an in-order burst port on the other."""

import numbers

from myhdl import ConcatSignal, Signal, always, always_comb, always_seq, block, concat, intbv, modbv

from eyestereo.hdl.common.checks import block_error, check_clock, check_distinct, check_int, check_port, check_reset
from eyestereo.hdl.interfaces.sdram_bus import SdramPins, SdramPort
from eyestereo.tools.sdram import ULX3S, mode_register, part as sdram_part

# init / run states
_WAIT, _PREALL, _REFS, _MRS, _MRDW, _RUN = range(6)


def _check(port, pins, part, clock_mhz, cas_latency, max_burst):
    check_port("port", port, SdramPort)
    check_port("pins", pins, SdramPins)
    try:
        p = sdram_part(part)
    except ValueError as e:
        raise block_error(f"parameter part: {e}") from None
    if isinstance(clock_mhz, bool) or not isinstance(clock_mhz, numbers.Real) or not 0 < clock_mhz <= 1000:
        raise block_error(f"parameter clock_mhz must be a number in (0, 1000], got {clock_mhz!r}")
    cl = check_int("cas_latency", cas_latency, 2, 3)
    if clock_mhz > p.max_mhz(cl) + 1e-9:
        raise block_error(f"parameter clock_mhz={clock_mhz} is too fast for {p.name} at CAS latency {cl}: at most "
                          f"{p.max_mhz(cl):.1f} MHz" + (" (CAS latency 3 runs faster)" if cl == 2 else ""))
    nb = check_int("max_burst", max_burst, 1, p.columns)
    if port.max_burst != nb:
        raise block_error(f"port has max_burst {port.max_burst}, the parameter max_burst is {nb}: they must match")
    if port.addr_bits != p.addr_bits:
        raise block_error(f"port has {port.addr_bits} address bits, {p.name} has {p.addr_bits} "
                          f"({p.words} words)")
    for name, got, want in (("port data_bits", port.data_bits, p.data_bits), ("pins data_bits", pins.data_bits,
                            p.data_bits), ("pins bank_bits", pins.bank_bits, p.bank_bits),
                            ("pins a_bits", pins.a_bits, p.a_bits)):
        if got != want:
            raise block_error(f"{name} is {got}, {p.name} needs {want}")
    if p.t_ras_max < 3 * p.t_refi:
        raise block_error(f"part {p.name}: t_ras_max ({p.t_ras_max} ns) is under 3 x tREFI ({3 * p.t_refi:.0f} ns): "
                          f"the open-row policy keeps a row open until the next refresh")
    ck = p.clocks(float(clock_mhz))
    if ck.rc < ck.rcd:
        raise block_error(f"part {p.name} at {clock_mhz} MHz: tRC ({ck.rc} clocks) is under tRCD ({ck.rcd}): a bank's "
                          f"tRCD is read from its tRC timer")
    if ck.refi < 2 * (refresh_margin(ck) + ck.rfc):
        raise block_error(f"part {p.name} at {clock_mhz} MHz: tREFI is {ck.refi} clocks, too short beside a "
                          f"refresh (closing the rows and tRP: {refresh_margin(ck)} clocks, tRFC: {ck.rfc})")
    return p, ck, cl, nb


def refresh_margin(ck) -> int:
    """Clocks a due refresh may need from the moment it stops every new command to its AUTO REFRESH
    reaching the part: the rows' tRAS / tWR (or tRC) to run out, PRECHARGE ALL, tRP, and the pin
    registers (plus one clock of slack)."""
    return max(max(ck.ras, ck.wr) + ck.rp, ck.rc) + 4


@block
def bank_state(clk, rst, c_act, c_pre, n_act, n_pre, d_preall, d_ref, d_wr, cur_bank, nxt_bank, act_row, in_row,
               oflag, row, aok, rok, pok, ihit, *, bank, ck):
    """One bank: its open flag and row, two timers and the flags the decision reads, all from flip-flops.

    The ACTIVATE timer counts tRC after ACTIVATE, tRP after PRECHARGE, tRFC after AUTO REFRESH; the
    PRECHARGE timer tRAS after ACTIVATE, tWR after a WRITE. A timer counts down to 0, when the command it
    guards may go (a spacing of n clocks loads n - 1), and its flag (``aok``, ``pok``) is the register of
    "0 at the next clock", so the decision reads a flip-flop, not a comparison. ``rok`` (tRCD passed) reads
    the ACTIVATE timer too: while the row is open that timer counts from the ACTIVATE, and tRCD has passed
    when it is at most tRC - tRCD. ``ihit``: the bank holds the row of the burst on the port (``in_row``)."""
    acnt = Signal(intbv(0, min=0, max=max(ck.rc, ck.rp, ck.rfc, 2)))
    pcnt = Signal(intbv(0, min=0, max=max(ck.ras, ck.wr, 2)))
    act, pre, wr = (Signal(bool(0)) for _ in range(3))
    rcd_at = ck.rc - ck.rcd + 1  # rok at the next clock when acnt is at most this now

    @always_comb
    def commands():
        # this bank's share of the clock's command, decoded from the burst that asked for it
        act.next = (c_act and cur_bank == bank) or (n_act and nxt_bank == bank)
        pre.next = d_preall or (c_pre and cur_bank == bank) or (n_pre and nxt_bank == bank)
        wr.next = d_wr and cur_bank == bank
        ihit.next = oflag and row == in_row

    @always_seq(clk.posedge, reset=rst)
    def timers():
        if act:
            oflag.next = True
            row.next = act_row
            acnt.next = ck.rc - 1
            aok.next = ck.rc <= 1
            rok.next = ck.rcd <= 1
            pcnt.next = ck.ras - 1
            pok.next = ck.ras <= 1
        else:
            if pre:
                oflag.next = False
                # tRP from now, or the longer tRC left
                if acnt > ck.rp:
                    acnt.next = acnt - 1
                    aok.next = False  # acnt - 1 >= tRP >= 1
                else:
                    acnt.next = ck.rp - 1
                    aok.next = ck.rp <= 1
            elif d_ref:
                acnt.next = ck.rfc - 1
                aok.next = ck.rfc <= 1
            elif acnt != 0:
                acnt.next = acnt - 1
                aok.next = acnt == 1
            # (after a PRECHARGE or a refresh rok is wrong, but the bank is closed: its ACTIVATE sets it again)
            rok.next = acnt <= rcd_at
            if wr:
                # tWR from now, or the longer tRAS left
                if pcnt > ck.wr:
                    pok.next = False  # pcnt - 1 >= tWR >= 1
                    pcnt.next = pcnt - 1
                else:
                    pok.next = ck.wr <= 1
                    pcnt.next = ck.wr - 1
            elif pcnt != 0:
                pok.next = pcnt == 1
                pcnt.next = pcnt - 1

    return commands, timers


@block
def sdram_controller(clk, rst, port, pins, *, part: str = ULX3S, clock_mhz: float = 100.0, cas_latency: int = 2,
                     max_burst: int = 8):
    """Bursts of 1..max_burst words in command order; an open row per bank; bank interleaving; auto refresh.

    The burst port and the pins, with a timing diagram, are :mod:`eyestereo.hdl.interfaces.sdram_bus`; the
    parts and their rules are :mod:`eyestereo.tools.sdram`.

    *Power-up*: after reset the controller waits the part's power-up time (``powerup_us``) with the
    command inhibited, then issues PRECHARGE ALL, the part's ``init_refreshes`` AUTO REFRESH commands and
    LOAD MODE REGISTER (burst length 1, sequential, the CAS latency), and takes commands tMRD later.

    *Bursts*: the mode register's burst length is 1, and a burst of n words is n READ or WRITE commands on
    consecutive clocks (the column counting up). This runs any length with no BURST TERMINATE and no
    interrupted-burst rules, byte masks per word come with each WRITE, and the command slot of any clock
    can go to another bank instead (below); the price is the command bus, busy in every clock of a burst.

    *Open rows*: each bank keeps its row open after a burst; a burst to an open row starts at once, to an
    idle bank after ACTIVATE (tRCD), on a row miss after PRECHARGE and ACTIVATE (tRP + tRCD). Rows close
    at every refresh (PRECHARGE ALL), well inside tRAS max.

    *Bank interleaving*: the controller holds the burst it carries out and the next one. While the first
    runs, the next one's bank, when it is another bank, is made ready in stolen command slots: its
    PRECHARGE and ACTIVATE take a clock each from the running burst (``wr_ready`` or the read words pause
    a clock), and tRP and tRCD elapse under the burst, so the next burst follows without a gap.

    *Refresh*: a counter makes a refresh due every tREFI (64 ms / 8192 rows, rounded down to clocks). A due
    refresh goes ahead of any burst not yet started (PRECHARGE ALL when tRAS and tWR allow, AUTO REFRESH
    tRP later); a burst already running finishes first, unless the next refresh would fall due before this
    one is done (a burst longer than what is left of tREFI), which pauses the burst: its bank is opened
    again after the refresh. A refresh is so never owed for a whole tREFI (never late) and rows never stay
    open for more than about tREFI.

    *Data bus*: a WRITE waits until the part has let go of the bus after the last READ's word (one idle
    bus cycle); reads follow writes at once.

    *The decision* (one command per clock, in this order: refresh, the running burst's PRECHARGE or
    ACTIVATE, the next burst's, the running burst's READ or WRITE) reads flip-flops, directly or through
    one multiplexer by the bursts' banks, so that it is a few LUTs deep: each bank's timer flags are
    registered (the value "timer at 0" one clock ahead), and each of the two bursts carries its bank's
    state as two flags, ``open`` and ``hit`` (its row is the open one), updated every clock from the
    command taken (an ACTIVATE or PRECHARGE of either burst, PRECHARGE ALL) and set when the burst is
    taken from the port (the bank's row compared with the port's address).
    The command is decoded per bank from the burst that asked for it; no bank-address multiplexer sits
    between the decision and the bank timers. The refresh's claim reads flags too (``run``: the power-up
    sequence done; ``owed_any``, ``owed_many``: refreshes owed), and so does a burst's end (``cur_last``).
    A burst on the port goes to the next-burst register only when there is none, so the stolen slot for
    the next burst's bank cannot be in the way then: the choice between the two registers reads the
    running burst's READ or WRITE without it, which keeps the next burst's bank flags off the path from
    the port (the masters' command register, in ``sdram_subsystem``) into the burst flags.

    Ports:
        clk, rst: clock and synchronous active-high reset (restarts the power-up sequence).
        port: :class:`~eyestereo.hdl.interfaces.sdram_bus.SdramPort`, the masters' bursts (its ``max_burst``
            the parameter's, its ``addr_bits`` the part's).
        pins: :class:`~eyestereo.hdl.interfaces.sdram_bus.SdramPins`, the part's pins.

    Parameters:
        part: the part, a name of :data:`eyestereo.tools.sdram.PARTS` with optional overrides
            (``"AS4C32M16SB-7:refresh_ms=8.192"``, :func:`eyestereo.tools.sdram.part`) or an SdramPart;
            default the ULX3S's AS4C32M16SB-7.
        clock_mhz: the clock the timings are counted in (at most the part's limit at the CAS latency:
            100 MHz at CL 2, 143 MHz at CL 3 for the -7 part).
        cas_latency: 2 or 3.
        max_burst: the longest burst, 1..columns (the port's ``max_burst``).

    Latency: a read burst to an open row gives its first word (``rd_valid``) ``cas_latency + 3`` clocks
    after the command is taken (5 at CL 2, 6 at CL 3), then a word per clock; an idle bank adds tRCD, a
    row miss tRP + tRCD (in clocks: 8 and 11 at 100 MHz, CL 2; the bench asserts all three); less when the
    bank was prepared under the previous burst, and up to tRP + tRFC + a burst more when a refresh is due.
    Writes are posted: a write burst to an open row has its first ``wr_ready`` the clock after it is taken.

    Resources: the pin registers (about 40 flip-flops, for the I/O blocks), per bank an open flag, a row
    register, two timers and three timer flags, two burst registers (current and next) with two bank
    flags each, the refresh counter and the read-flag pipeline. Measured (docs/memory.md, AS4C32M16SB-7,
    max_burst 8): 100 MHz CL 2: 572 LUT / 255 FF (Spartan-3E), 573 LUT4 / 255 FF (ECP5), LFE5U-25F fmax 119.9 /
    125.8 / 126.2 MHz (min / median / max over nextpnr seeds 1-4; before the registered flags 695 LUT4 / 252
    FF and 88.0 MHz); 133 MHz CL 3: 683 LUT4 / 261 FF, 122.4 / 130.6 / 132.8 MHz (under its own clock: its
    worst paths, the decision into the bank timers and the pin registers, are 6-8 LUTs with 6 ns of
    routing; 133 MHz would need the decision registered, a clock more of latency). In ``sdram_subsystem``
    (max_burst 1, the arbiter before it) 118.6 / 125.6 / 131.2 MHz.
    """
    check_clock(clk)
    check_reset(rst)
    p, ck, cl, nb_max = _check(port, pins, part, clock_mhz, cas_latency, max_burst)
    check_distinct(dict(pins=pins), dict(clk=clk, rst=rst, port=port))

    nbanks, bb, rb, cb, ab = p.banks, p.bank_bits, p.row_bits, p.col_bits, p.a_bits
    be_bits = p.data_bits // 8
    mode_word = mode_register(1, cl)
    a10 = 1 << 10  # A10 high: PRECHARGE ALL
    mrd_wait = max(ck.mrd - 2, 0)
    margin = refresh_margin(ck)
    refi_max = ck.refi
    wait_max = max(ck.powerup, 1)
    left_2 = min(2, nb_max)  # cur_left before the last word of a burst

    # --- the state ------------------------------------------------------------------------------------
    state = Signal(intbv(_WAIT, min=0, max=_RUN + 1))
    # the power-up wait, then the initial refreshes still to issue, then tMRD
    icnt = Signal(intbv(wait_max - 1, min=0, max=max(wait_max, p.init_refreshes, mrd_wait + 1)))
    refi = Signal(intbv(refi_max - 1, min=0, max=refi_max))
    refi_low = Signal(bool(0))  # refi < margin: a running burst must give way to the owed refresh
    owed = Signal(intbv(0, min=0, max=16))
    # owed != 0, owed > 1 and state == _RUN as flip-flops: the refresh decision is one LUT from registers
    owed_any, owed_many, run = Signal(bool(0)), Signal(bool(0)), Signal(bool(0))
    rrd = Signal(intbv(0, min=0, max=max(ck.rrd, 2)))

    is_open = [Signal(bool(0)) for _ in range(nbanks)]
    rows = [Signal(intbv(0)[rb:]) for _ in range(nbanks)]
    aok = [Signal(bool(1)) for _ in range(nbanks)]
    rok = [Signal(bool(1)) for _ in range(nbanks)]
    pok = [Signal(bool(1)) for _ in range(nbanks)]
    ihit = [Signal(bool(0)) for _ in range(nbanks)]

    def vec(sigs):
        return ConcatSignal(*reversed(sigs)) if len(sigs) > 1 else sigs[0]

    open_v, aok_v, rok_v, pok_v, ihit_v = (vec(s) for s in (is_open, aok, rok, pok, ihit))
    all_banks = (1 << nbanks) - 1

    # current and next burst, each with its bank's state: open, and open on the burst's row (hit)
    cur_valid, cur_we, cur_started = Signal(bool(0)), Signal(bool(0)), Signal(bool(0))
    cur_bank, cur_row, cur_col = Signal(intbv(0)[bb:]), Signal(intbv(0)[rb:]), Signal(modbv(0)[cb:])
    cur_left = Signal(intbv(0, min=0, max=nb_max + 1))
    cur_last = Signal(bool(0))  # cur_left == 1, from a flip-flop
    cur_open, cur_hit = Signal(bool(0)), Signal(bool(0))
    nxt_valid, nxt_we = Signal(bool(0)), Signal(bool(0))
    nxt_bank, nxt_row, nxt_col = Signal(intbv(0)[bb:]), Signal(intbv(0)[rb:]), Signal(intbv(0)[cb:])
    nxt_len = Signal(intbv(0)[port.len_bits:])
    nxt_open, nxt_hit = Signal(bool(0)), Signal(bool(0))
    in_bank, in_row, in_col = Signal(intbv(0)[bb:]), Signal(intbv(0)[rb:]), Signal(intbv(0)[cb:])
    in_open, in_hit, in_same, eq_ci, eq_cn = (Signal(bool(0)) for _ in range(5))

    # the flags the decision reads (one LUT level from flip-flops)
    cur_aok, cur_rok, cur_pok, nxt_aok, nxt_pok = (Signal(bool(0)) for _ in range(5))
    any_open, all_aok, all_pok, same_bank, rrd_ok, ref_now, wblock = (Signal(bool(0)) for _ in range(7))
    # the decision of this clock: which command, for whom
    i_preall, i_ref, i_mrs, r_preall, r_ref = (Signal(bool(0)) for _ in range(5))
    go, cur_prep, nxt_prep = (Signal(bool(0)) for _ in range(3))
    c_pre, c_act, n_pre, n_act, rw, rw_cur = (Signal(bool(0)) for _ in range(6))
    d_cs, d_ras_n, d_cas_n, d_we_n = Signal(bool(0)), Signal(bool(1)), Signal(bool(1)), Signal(bool(1))
    d_preall, d_ref, d_mrs, d_rd, d_wr = (Signal(bool(0)) for _ in range(5))
    d_ba = Signal(intbv(0)[bb:])
    d_a = Signal(intbv(0)[ab:])
    act_row = Signal(intbv(0)[rb:])
    take, load_cur, take_nxt = Signal(bool(0)), Signal(bool(0)), Signal(bool(0))
    rpipe = Signal(intbv(0)[cl + 1:])  # bit j: a READ was decided j + 1 clocks ago

    insts = []

    # --- per bank: timers, open row, the flags the decision reads ---------------------------------------
    for b in range(nbanks):
        insts.append(bank_state(clk, rst, c_act, c_pre, n_act, n_pre, d_preall, d_ref, d_wr, cur_bank, nxt_bank,
                                act_row, in_row, is_open[b], rows[b], aok[b], rok[b], pok[b], ihit[b], bank=b, ck=ck))

    # --- the decision: one command per clock -------------------------------------------------------------
    @always_comb
    def fields_in():
        in_col.next = port.cmd_addr[cb:0]
        in_bank.next = port.cmd_addr[cb + bb:cb]
        in_row.next = port.cmd_addr[cb + bb + rb:cb + bb]

    @always_comb
    def port_flags():
        # the state of the bank a burst on the port asks for, and how it relates to the running burst
        in_open.next = open_v[in_bank]
        in_hit.next = ihit_v[in_bank]
        in_same.next = in_bank == cur_bank
        eq_ci.next = in_row == cur_row
        eq_cn.next = nxt_row == cur_row

    @always_comb
    def status():
        wblock.next = rpipe != 0
        port.cmd_ready.next = run and not nxt_valid

    @always_comb
    def bank_flags():
        cur_aok.next = aok_v[cur_bank]
        cur_rok.next = rok_v[cur_bank]
        cur_pok.next = pok_v[cur_bank]
        nxt_aok.next = aok_v[nxt_bank]
        nxt_pok.next = pok_v[nxt_bank]
        any_open.next = open_v != 0
        all_aok.next = aok_v == all_banks
        all_pok.next = pok_v == all_banks
        same_bank.next = nxt_bank == cur_bank
        rrd_ok.next = rrd == 0

    @always_comb
    def refresh_due():
        # refresh ahead of any burst not started, or of a running one when the next refresh is close
        ref_now.next = run and owed_any and (not cur_started or owed_many or refi_low)

    @always_comb
    def wants():
        i_preall.next = state == _WAIT and icnt == 0
        i_ref.next = state == _REFS and all_aok
        i_mrs.next = state == _MRS and all_aok
        # a refresh: close every row, then AUTO REFRESH
        r_preall.next = ref_now and any_open and all_pok
        r_ref.next = ref_now and not any_open and all_aok
        go.next = run and not ref_now
        # the running burst's bank needs a PRECHARGE (row miss) or an ACTIVATE (idle), and it may go
        cur_prep.next = cur_valid and not cur_hit and ((cur_open and cur_pok) or (not cur_open and cur_aok and rrd_ok))
        # the next burst's bank, another one, the same (bank interleaving)
        nxt_prep.next = (nxt_valid and not same_bank and not nxt_hit
                         and ((nxt_open and nxt_pok) or (not nxt_open and nxt_aok and rrd_ok)))

    @always_comb
    def decide():
        c_pre.next = go and cur_prep and cur_open
        c_act.next = go and cur_prep and not cur_open
        n_pre.next = go and not cur_prep and nxt_prep and nxt_open
        n_act.next = go and not cur_prep and nxt_prep and not nxt_open
        # (cur_hit rules out cur_prep) the running burst's READ or WRITE may go, unless the next burst's
        # bank takes the slot
        rw_cur.next = go and cur_valid and cur_hit and cur_rok and not (cur_we and wblock)
        rw.next = rw_cur and not nxt_prep

    @always_comb
    def command():
        d_preall.next = i_preall or r_preall
        d_ref.next = i_ref or r_ref
        d_mrs.next = i_mrs
        d_rd.next = rw and not cur_we
        d_wr.next = rw and cur_we
        # the command's code (tools.sdram.CMD): RAS low for ACT, PRE, REF, MRS; CAS low for READ, WRITE, REF,
        # MRS; WE low for PRE, WRITE, MRS
        d_ras_n.next = not (i_preall or r_preall or i_ref or r_ref or i_mrs or c_pre or c_act or n_pre or n_act)
        d_cas_n.next = not (i_ref or r_ref or i_mrs or rw)
        d_we_n.next = not (i_preall or r_preall or i_mrs or c_pre or n_pre or (rw and cur_we))
        d_cs.next = (i_preall or r_preall or i_ref or r_ref or i_mrs or c_pre or c_act or n_pre or n_act or rw)

    @always_comb
    def row_of_act():
        act_row.next = cur_row if c_act else nxt_row

    @always_comb
    def address():
        d_ba.next = nxt_bank if (n_pre or n_act) else cur_bank
        if i_preall or r_preall:
            d_a.next = a10
        elif i_mrs:
            d_a.next = mode_word
        elif rw:
            d_a.next = cur_col
        elif c_pre or n_pre:
            d_a.next = 0  # A10 low: this bank only
        else:
            d_a.next = act_row

    @always_comb
    def handshake():
        port.wr_ready.next = d_wr
        take.next = port.cmd_valid and run and not nxt_valid
        load_cur.next = (not cur_valid) or (rw and cur_last)
        # a burst taken goes to the next-burst register when the running one does not end in this clock;
        # take implies no next burst, hence no nxt_prep: rw_cur stands for rw here, which keeps the next
        # burst's bank flags (and the stolen slot) off this path from the port into the burst flags
        take_nxt.next = take and cur_valid and not (rw_cur and cur_last)

    insts += [fields_in, port_flags, status, bank_flags, refresh_due, wants, decide, command, row_of_act, address,
              handshake]

    # --- sequencing: power-up, refresh debt, the two burst registers --------------------------------------
    @always_seq(clk.posedge, reset=rst)
    def sequencer():
        if state == _WAIT:
            if icnt == 0:
                state.next = _REFS
                icnt.next = p.init_refreshes - 1
            else:
                icnt.next = icnt - 1
        elif state == _REFS:
            if d_ref:
                if icnt == 0:
                    state.next = _MRS
                else:
                    icnt.next = icnt - 1
        elif state == _MRS:
            if d_mrs:
                state.next = _MRDW
                icnt.next = mrd_wait
        elif state == _MRDW:
            if icnt == 0:
                state.next = _RUN
                run.next = True
            else:
                icnt.next = icnt - 1
        refi_low.next = state == _RUN and refi != 0 and refi <= margin
        if state != _RUN:
            refi.next = refi_max - 1
        elif refi == 0:
            refi.next = refi_max - 1
            if not (d_ref and owed_any) and owed != 15:
                owed.next = owed + 1
                owed_any.next = True
                owed_many.next = owed_any
        else:
            refi.next = refi - 1
            if d_ref and owed_any:
                owed.next = owed - 1
                owed_any.next = owed_many
                owed_many.next = owed > 2
        if c_act or n_act:
            rrd.next = ck.rrd - 1
        elif rrd != 0:
            rrd.next = rrd - 1

    @always_seq(clk.posedge, reset=rst)
    def bursts():
        if load_cur:
            if nxt_valid:
                # (the clock's command is the ending burst's READ or WRITE: no bank changes)
                cur_valid.next = True
                cur_we.next = nxt_we
                cur_bank.next = nxt_bank
                cur_row.next = nxt_row
                cur_col.next = nxt_col
                cur_left.next = nxt_len
                cur_last.next = nxt_len == 1
                cur_open.next = nxt_open
                cur_hit.next = nxt_hit
                cur_started.next = False
                nxt_valid.next = False
            elif take:
                # (the clock's command is the ending burst's READ or WRITE, or a refresh's)
                cur_valid.next = True
                cur_we.next = port.cmd_we
                cur_bank.next = in_bank
                cur_row.next = in_row
                cur_col.next = in_col
                cur_left.next = port.cmd_len
                cur_last.next = port.cmd_len == 1
                cur_open.next = in_open and not d_preall
                cur_hit.next = in_hit and not d_preall
                cur_started.next = False
            else:
                cur_valid.next = False
                cur_started.next = False
        else:
            if rw:
                cur_col.next = cur_col + 1
                cur_left.next = cur_left - 1
                # (with max_burst 1 a READ or WRITE always ends its burst and this never runs; the constant
                # stays inside cur_left's range, which GHDL's synthesis needs)
                cur_last.next = cur_left == left_2
                cur_started.next = True
            cur_open.next = (cur_open or c_act) and not c_pre and not d_preall
            cur_hit.next = (cur_hit or c_act) and not c_pre and not d_preall
        if take_nxt:
            # (the clock's command is the running burst's or a refresh's)
            nxt_valid.next = True
            nxt_we.next = port.cmd_we
            nxt_len.next = port.cmd_len
            nxt_bank.next = in_bank
            nxt_row.next = in_row
            nxt_col.next = in_col
            nxt_open.next = not d_preall and not (c_pre and in_same) and (in_open or (c_act and in_same))
            nxt_hit.next = not d_preall and not (c_pre and in_same) and (in_hit or (c_act and in_same and eq_ci))
        else:
            nxt_open.next = (not d_preall and not n_pre and not (c_pre and same_bank)
                             and (nxt_open or n_act or (c_act and same_bank)))
            nxt_hit.next = (not d_preall and not n_pre and not (c_pre and same_bank)
                            and (nxt_hit or n_act or (c_act and same_bank and eq_cn)))

    insts += [sequencer, bursts]

    # --- pins: every output from a flip-flop ------------------------------------------------------------
    no_bytes = (1 << be_bits) - 1
    be_n = Signal(intbv(no_bytes)[be_bits:])

    @always_comb
    def byte_mask():
        be_n.next = ~port.wr_be

    @always_seq(clk.posedge, reset=rst)
    def command_pins():
        pins.cke.next = True
        pins.cs_n.next = not d_cs
        pins.ras_n.next = d_ras_n
        pins.cas_n.next = d_cas_n
        pins.we_n.next = d_we_n
        pins.dq_oe.next = d_wr
        if state != _RUN:
            pins.dqm.next = no_bytes
        elif d_wr:
            pins.dqm.next = be_n
        else:
            pins.dqm.next = 0

    @always(clk.posedge)
    def address_pins():
        pins.ba.next = d_ba
        pins.a.next = d_a
        pins.dq_o.next = port.wr_data

    # read side: the part drives a READ's word CL clocks after the pins carry it; the input register
    # samples it and is rd_data itself
    @always_seq(clk.posedge, reset=rst)
    def read_flags():
        rpipe.next = concat(rpipe[cl:0], d_rd)
        port.rd_valid.next = rpipe[cl]

    @always(clk.posedge)
    def read_data():
        port.rd_data.next = pins.dq_i

    insts += [byte_mask, command_pins, address_pins, read_flags, read_data]
    return insts
