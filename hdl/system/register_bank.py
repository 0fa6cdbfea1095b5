"""Register bank: the register map of eyestereo.tools.regmap on an AXI4-Lite slave, elaborated from the table."""

from __future__ import annotations

from myhdl import ConcatSignal, Signal, always, always_comb, always_seq, block, enum, intbv
from myhdl._Signal import _Signal

from eyestereo.hdl.interfaces.axil import check_axil
from eyestereo.hdl.common.checks import block_error, check_clock, check_reset, checked
from eyestereo.hdl.common.registers import assign
from eyestereo.hdl.interfaces.sram_bus import HostPort, StatPort, check_bundle
from eyestereo.tools.constants import FRAME_HEIGHT, FRAME_WIDTH
from eyestereo.tools.regmap import OKAY, REGMAP, SLVERR, WRITABLE, Register, RegisterMap, check_frame_size

__all__ = ["RegisterPorts", "register_bank", "read_wait", "WINDOW_PORTS"]

#: The bank's window ports in its signature, and the StatPort shape each needs (address bits, data bits).
WINDOW_PORTS = ("arb", "fcount")


def _sig(width: int, value: int = 0):
    return Signal(bool(value)) if width == 1 else Signal(intbv(value)[width:])


def _index_bits(count: int) -> int:
    return max(1, (count - 1).bit_length())


class RegisterPorts:
    """The bank's register-side ports, one per field of the table (ports ``<arg>_<field>``, e.g. ``regs_mode``).

    * ``rw`` fields: outputs holding the field (``mode``, ``k_left``, ...); 1-bit fields are ``Signal(bool)``.
    * ``pulse`` fields: outputs high for one clock per 1 written (``start``, ``stop``, ...).
    * ``status`` fields: inputs (``busy``, ``frames``, ``dropped_left``, ...).
    * each ``array``: a write port ``<port>_we`` (one clock), ``<port>_addr`` (word index),
      ``<port>_data`` (the field's width): ``thr_left_we/_addr/_data`` is the pre-threshold's
      ``thr_we/thr_addr/thr_data``.
    """

    def __init__(self, regmap: RegisterMap = REGMAP):
        self._outputs, self._inputs = [], []
        for r in regmap:
            if r.kind in ("rw", "pulse", "status"):
                for f in r.fields:
                    setattr(self, f.name, _sig(f.width, f.reset if r.kind == "rw" else 0))
                    (self._inputs if r.kind == "status" else self._outputs).append(f.name)
            elif r.kind == "array":
                setattr(self, f"{r.port}_we", Signal(bool(0)))
                setattr(self, f"{r.port}_addr", Signal(intbv(0)[_index_bits(r.count):]))
                setattr(self, f"{r.port}_data", Signal(intbv(0)[r.fields[0].width:]))
                self._outputs += [f"{r.port}_we", f"{r.port}_addr", f"{r.port}_data"]

    def fields(self) -> list[str]:
        return self._outputs + self._inputs

    def outputs(self) -> list[str]:
        return list(self._outputs)

    def inputs(self) -> list[str]:
        return list(self._inputs)


def read_wait(regmap: RegisterMap = REGMAP) -> int:
    """Clocks from a local read's address register to the data capture: the registered decode, then the
    slowest window port's latency (the read multiplexer's output register adds the last one)."""
    return 1 + max([r.latency for r in regmap.of_kind("window")] + [1])


# ---- small blocks the bank is built of (each of fixed shape, so that the whole converts) -----------------
@block
def rb_hit(clk, rst, waddr, in_local, wr_now, hit, we, *, base: int, lo: int, hi: int, count: int):
    """hit (registered): the word address lies in a register's region ``waddr[hi:lo] == base`` (and its
    index ``waddr[lo:0] < count`` where the region is larger than the register); we (a writable register's,
    None for the others): hit in the clock the bank writes (``wr_now``)."""
    full = count == 1 << lo

    if full:
        @always_seq(clk.posedge, reset=rst)
        def match():
            hit.next = in_local and waddr[hi:lo] == base
    else:
        @always_seq(clk.posedge, reset=rst)
        def match():
            hit.next = in_local and waddr[hi:lo] == base and waddr[lo:0] < count

    if we is None:
        return match

    @always_comb
    def write():
        we.next = wr_now and hit

    return match, write


@block
def rb_rw(clk, rst, we, wdata, wmask, q, *, mask: int):
    """A rw register: the bytes of ``wmask`` within the fields' ``mask`` take ``wdata`` when ``we``."""
    m = Signal(intbv(mask)[32:])  # never driven: a constant

    @always_seq(clk.posedge, reset=rst)
    def reg():
        if we:
            q.next = (q & ~(wmask & m)) | (wdata & wmask & m)

    return reg


@block
def rb_pulse(clk, rst, we, wdata, wmask, q, *, mask: int):
    """A command register: the written ones of ``mask`` for one clock."""
    m = Signal(intbv(mask)[32:])

    @always_seq(clk.posedge, reset=rst)
    def reg():
        if we:
            q.next = wdata & wmask & m
        else:
            q.next = 0

    return reg


@block
def rb_field(q, out, *, lsb: int, width: int):
    """An output port: bits ``lsb + width - 1 .. lsb`` of a register."""
    if width == 1:
        @always_comb
        def comb():
            out.next = q[lsb]
    else:
        @always_comb
        def comb():
            out.next = q[lsb + width:lsb]

    return comb


@block
def rb_array(clk, rst, we, idx, wdata, wmask, word, p_we, p_addr, p_data, *, count: int, width: int):
    """An array register: ``count`` words of ``width`` bits in LUT-RAM (combinational read), a written
    flag per word (0 is read until a word is written after reset), and the write port."""
    mem = [Signal(intbv(0)[width:]) for _ in range(count)]
    written = Signal(intbv(0)[count:])
    cur = Signal(intbv(0)[width:])
    new = Signal(intbv(0)[width:])
    wm = Signal(intbv(0)[width:])
    wd = Signal(intbv(0)[width:])
    pad = Signal(intbv(0)[32 - width:]) if width < 32 else None

    valid = Signal(bool(0))

    @always_seq(clk.posedge, reset=rst)
    def flag():
        # registered: the address is held for at least one clock before a write or a read's capture, and
        # a flag register stops ABC from copying the 16:1 flag multiplexer into every data bit
        valid.next = written[idx]

    @always_comb
    def read():
        if valid:
            cur.next = mem[idx]
        else:
            cur.next = 0

    @always_comb
    def merge():
        wm.next = wmask[width:0]
        wd.next = wdata[width:0]

    @always_comb
    def merged():
        new.next = (cur & ~wm) | (wd & wm)

    @always(clk.posedge)
    def store():  # no reset: LUT-RAM
        if we:
            mem[idx].next = new

    @always_seq(clk.posedge, reset=rst)
    def port():
        p_we.next = we
        if we:
            written.next[idx] = 1
            p_addr.next = idx
            p_data.next = new

    insts = [flag, read, merge, merged, store, port]
    if pad is None:
        @always_comb
        def out():
            word.next = cur
    else:
        full = ConcatSignal(pad, cur)

        @always_comb
        def out():
            word.next = full
    insts.append(out)
    return insts


@block
def rb_window(waddr, data, addr, word, *, bits: int):
    """A window: its read port's address from the word address; the read word from its data."""
    pad = Signal(intbv(0)[32 - len(data):]) if len(data) < 32 else None
    full = data if pad is None else ConcatSignal(pad, data)

    @always_comb
    def comb():
        addr.next = waddr[bits:0]
        word.next = full

    return comb


@block
def rb_gate_or(hit, a, b, out):
    """out = (a if hit else 0) | b: one step of the read multiplexer (one-hot hits)."""

    @always_comb
    def comb():
        if hit:
            out.next = a | b
        else:
            out.next = b

    return comb


@block
def rb_any(bits, out):
    @always_comb
    def comb():
        out.next = bits != 0

    return comb


def _pack(r: Register, sigs: dict):
    """A register's read word from its fields' signals: ConcatSignal with zeros in the gaps."""
    parts, top = [], 32
    for f in sorted(r.fields, key=lambda f: -f.lsb):
        gap = top - (f.lsb + f.width)
        if gap:
            parts.append(intbv(0)[gap:])
        parts.append(sigs[f.name])
        top = f.lsb
    if top:
        parts.append(intbv(0)[top:])
    return parts[0] if len(parts) == 1 else ConcatSignal(*parts)


def _check_ports(regs: RegisterPorts, regmap: RegisterMap) -> None:
    check_bundle("regs", regs, RegisterPorts)
    want = RegisterPorts(regmap)
    for n in want.fields():
        got, exp = getattr(regs, n, None), getattr(want, n)
        ok = isinstance(got, _Signal) and type(got.val) is type(exp.val) and (
            isinstance(exp.val, bool) or len(got) == len(exp))
        if not ok:
            w = 1 if isinstance(exp.val, bool) else len(exp)
            raise block_error(f"port regs: field {n} must be a {'Signal(bool)' if w == 1 else f'{w}-bit Signal'} "
                              f"(RegisterPorts of the register map)")


@block
def register_bank(clk, rst, bus, regs, arb, fcount, host, *, width: int = FRAME_WIDTH, height: int = FRAME_HEIGHT):
    """The register map (:data:`eyestereo.tools.regmap.REGMAP`, docs/registers.md) on an AXI4-Lite slave.

    Everything is elaborated from the table: one output port per ``rw`` and ``pulse`` field, one input
    per ``status`` field, a write port per ``array`` (``regs``: :class:`RegisterPorts`), the windows'
    read ports (``arb``, ``fcount``), the SRAM window on the arbiter's host port (``host``), the address
    decoder (a registered one-hot hit per register) and the read multiplexer (an AND-OR chain over the
    hits, registered). Bus behaviour (docs/registers.md): byte strobes honoured, SLVERR and read data 0
    for unmapped addresses and writes to read-only registers, one access at a time, reads and writes
    alternating when both wait. Timing: :mod:`eyestereo.hdl.interfaces.axil`.

    Ports:
        clk, rst: the bus clock (the memory clock, 100 MHz, in the system: the arbiter's status port and
            host port are in it) and synchronous active-high reset (every register to its reset value).
        bus: :class:`~eyestereo.hdl.interfaces.axil.AxiLite` slave, 23 address bits (the map's), 32 data bits.
        regs: :class:`RegisterPorts` of the map.
        arb: :class:`~eyestereo.hdl.interfaces.sram_bus.StatPort` (5 address bits, 32 data bits), to the arbiter's
            status port (address out, data in 2 clocks later).
        fcount: StatPort (5 address bits, 16 data bits): features per block, address camera << 4 | block,
            data 2 clocks later (the feature counter's read port).
        host: :class:`~eyestereo.hdl.interfaces.sram_bus.HostPort` (20 address bits, 16 data bits), to the arbiter.

    Parameters:
        width, height: the frame size the GEOMETRY register reports (2..4096: the rule
            :func:`eyestereo.tools.regmap.check_frame_size`, which the bank's model checks too).

    Latency (bus clocks, measured on GHDL by the bench): a register write's response is valid 3 clocks
    after its address and data moved (the output ports change at the edge before); a register or window
    read's data 5 clocks after its address moved (a decode register, the windows' 2 clocks, the
    multiplexer's register); SRAM accesses add the host port's wait. One access at a time: at most one
    register read per 7 clocks (14 M reads/s at 100 MHz), above the thesis's 12.5 M words/s host bridge.

    Resources (make synth: Yosys xc3se on GHDL's netlist of the VHDL, the netlist the Icarus regression
    runs): 628 LUT + 40 LUT-RAM (the two threshold copies), 247 FF, no block RAM or multiplier; 147 MHz
    estimated on the Spartan-3E -4 (eyestereo.hdl.flow.sta; its 495 port bits fit no ECP5 package for
    nextpnr). Most LUTs are the read multiplexer of the ~290 readable bits.
    """
    regmap = REGMAP
    check_clock(clk)
    check_reset(rst)
    check_axil("bus", bus, addr_bits=regmap.addr_bits)
    _check_ports(regs, regmap)
    for name, port in (("arb", arb), ("fcount", fcount)):
        check_bundle(name, port, StatPort)
        r = next(r for r in regmap.of_kind("window") if r.port == name)
        if len(port.addr) != _index_bits(r.count) or len(port.data) != r.fields[0].width:
            raise block_error(f"port {name} needs {_index_bits(r.count)} address bits and {r.fields[0].width} data "
                              f"bits, got {len(port.addr)} and {len(port.data)}")
    check_bundle("host", host, HostPort)
    mem = regmap.of_kind("memory")[0]
    if len(host.req_addr) != _index_bits(mem.count) or len(host.req_wdata) != 16:
        raise block_error(f"port host needs {_index_bits(mem.count)} address bits and 16 data bits")
    width, height = checked(check_frame_size, width, height)
    params = dict(width=width, height=height)
    if {r.port for r in regmap.of_kind("window")} != set(WINDOW_PORTS):
        raise block_error(f"the register map's windows must be {WINDOW_PORTS} (the bank's ports)")

    WB = regmap.addr_bits - 2                      # word-address bits
    LB = (regmap.local_bytes // 4 - 1).bit_length()  # local word-index bits
    RD_WAIT = read_wait(regmap)

    t_state = enum("IDLE", "AR", "AW", "RD", "WR", "SRAM_RQ", "SRAM_RSP", "B", "R")
    state = Signal(t_state.IDLE)
    waddr = Signal(intbv(0)[WB:])
    wdata = Signal(intbv(0)[32:])
    wmask = Signal(intbv(0)[32:])
    wstrb = Signal(intbv(0)[4:])
    cnt = Signal(intbv(0, min=0, max=RD_WAIT + 1))
    last_wr = Signal(bool(0))
    in_local = Signal(bool(0))
    mem_sel = Signal(bool(0))
    wr_now = Signal(bool(0))
    # the fsm's registers behind the bus and host outputs, copied to the ports below (signals of their own:
    # they hold 0, not 'U', before the first reset, when the bus model already samples them)
    awready, wready, arready = Signal(bool(0)), Signal(bool(0)), Signal(bool(0))
    bvalid, rvalid = Signal(bool(0)), Signal(bool(0))
    bresp, rresp = Signal(intbv(0)[2:]), Signal(intbv(0)[2:])
    rdata = Signal(intbv(0)[32:])
    req_valid, req_we = Signal(bool(0)), Signal(bool(0))

    insts = []
    words, hits, writable = [], [], []
    for r in regmap:
        if r.kind == "memory":
            continue
        hit = Signal(bool(0))
        we = Signal(bool(0)) if r.kind in WRITABLE else None
        lo = (r.span // 4 - 1).bit_length()
        insts.append(rb_hit(clk, rst, waddr, in_local, wr_now, hit, we, base=(r.offset // 4) >> lo, lo=lo, hi=LB,
                            count=r.count))
        hits.append(hit)
        if we is not None:
            writable.append(hit)
        if r.kind == "const":
            words.append((hit, Signal(intbv(r.reset_value(params))[32:])))
        elif r.kind == "rw":
            q = Signal(intbv(r.reset_value(params))[32:])
            insts.append(rb_rw(clk, rst, we, wdata, wmask, q, mask=r.mask))
            insts += [rb_field(q, getattr(regs, f.name), lsb=f.lsb, width=f.width) for f in r.fields]
            words.append((hit, q))
        elif r.kind == "pulse":
            q = Signal(intbv(0)[32:])
            insts.append(rb_pulse(clk, rst, we, wdata, wmask, q, mask=r.mask))
            insts += [rb_field(q, getattr(regs, f.name), lsb=f.lsb, width=f.width) for f in r.fields]
        elif r.kind == "status":
            words.append((hit, _pack(r, {f.name: getattr(regs, f.name) for f in r.fields})))
        elif r.kind == "array":
            word = Signal(intbv(0)[32:])
            n = _index_bits(r.count)
            insts.append(rb_array(clk, rst, we, waddr(n, 0), wdata, wmask, word, getattr(regs, f"{r.port}_we"),
                                getattr(regs, f"{r.port}_addr"), getattr(regs, f"{r.port}_data"), count=r.count,
                                width=r.fields[0].width))
            words.append((hit, word))
        elif r.kind == "window":
            port = arb if r.port == "arb" else fcount
            word = Signal(intbv(0)[32:])
            insts.append(rb_window(waddr, port.data, port.addr, word, bits=len(port.addr)))
            words.append((hit, word))

    # read multiplexer: an AND-OR chain over the one-hot hits, then a register
    acc = Signal(intbv(0)[32:])  # never driven: 0
    for hit, word in words:
        nxt = Signal(intbv(0)[32:])
        insts.append(rb_gate_or(hit, word, acc, nxt))
        acc = nxt
    mux_q = Signal(intbv(0)[32:])
    rd_ok, wr_ok = Signal(bool(0)), Signal(bool(0))
    insts.append(rb_any(ConcatSignal(*hits) if len(hits) > 1 else hits[0], rd_ok))
    insts.append(rb_any(ConcatSignal(*writable) if len(writable) > 1 else writable[0], wr_ok))

    @always(clk.posedge)
    def mux_reg():
        mux_q.next = acc

    @always_comb
    def decode():
        in_local.next = waddr[WB:LB] == 0
        mem_sel.next = waddr[WB - 1]
        wr_now.next = state == t_state.WR and cnt == 1 and not mem_sel

    @always_seq(clk.posedge, reset=rst)
    def fsm():
        if state == t_state.IDLE:
            if bus.arvalid and (not (bus.awvalid and bus.wvalid) or last_wr):
                arready.next = 1
                state.next = t_state.AR
            elif bus.awvalid and bus.wvalid:
                awready.next = 1
                wready.next = 1
                state.next = t_state.AW
        elif state == t_state.AR:  # arvalid is high (held until it moves): it moves at this edge
            arready.next = 0
            waddr.next = bus.araddr[WB + 2:2]
            last_wr.next = 0
            cnt.next = 0
            state.next = t_state.RD
        elif state == t_state.AW:
            awready.next = 0
            wready.next = 0
            waddr.next = bus.awaddr[WB + 2:2]
            wdata.next = bus.wdata
            wstrb.next = bus.wstrb
            m = intbv(0)[32:]
            if bus.wstrb[0]:
                m[8:0] = 0xFF
            if bus.wstrb[1]:
                m[16:8] = 0xFF
            if bus.wstrb[2]:
                m[24:16] = 0xFF
            if bus.wstrb[3]:
                m[32:24] = 0xFF
            wmask.next = m
            last_wr.next = 1
            cnt.next = 0
            state.next = t_state.WR
        elif state == t_state.WR:
            if mem_sel:
                if wstrb[2:0] != 0:
                    req_valid.next = 1
                    req_we.next = 1
                    state.next = t_state.SRAM_RQ
                else:
                    bresp.next = OKAY
                    bvalid.next = 1
                    state.next = t_state.B
            elif cnt == 0:
                cnt.next = 1  # the hits are registered: they are valid in the next clock
            else:  # cnt == 1: wr_now is high, the registers take the write at this edge
                if wr_ok:
                    bresp.next = OKAY
                else:
                    bresp.next = SLVERR
                bvalid.next = 1
                state.next = t_state.B
        elif state == t_state.RD:
            if mem_sel:
                req_valid.next = 1
                req_we.next = 0
                state.next = t_state.SRAM_RQ
            elif cnt == RD_WAIT:
                if rd_ok:
                    rdata.next = mux_q
                    rresp.next = OKAY
                else:
                    rdata.next = 0
                    rresp.next = SLVERR
                rvalid.next = 1
                state.next = t_state.R
            else:
                cnt.next = cnt + 1
        elif state == t_state.SRAM_RQ:
            if host.req_ready:  # req_valid is high: the request moves at this edge
                req_valid.next = 0
                if req_we:
                    bresp.next = OKAY
                    bvalid.next = 1
                    state.next = t_state.B
                else:
                    state.next = t_state.SRAM_RSP
        elif state == t_state.SRAM_RSP:
            if host.rsp_valid:
                rdata.next = host.rsp_data
                rresp.next = OKAY
                rvalid.next = 1
                state.next = t_state.R
        elif state == t_state.B:
            if bus.bready:
                bvalid.next = 0
                state.next = t_state.IDLE
        else:  # R
            if bus.rready:
                rvalid.next = 0
                state.next = t_state.IDLE

    insts += [assign(q, port) for q, port in (
        (awready, bus.awready), (wready, bus.wready), (arready, bus.arready), (bvalid, bus.bvalid),
        (bresp, bus.bresp), (rvalid, bus.rvalid), (rresp, bus.rresp), (rdata, bus.rdata),
        (req_valid, host.req_valid), (req_we, host.req_we))]

    @always_comb
    def outputs():
        host.req_addr.next = waddr[len(host.req_addr):0]
        host.req_wdata.next = wdata[16:0]
        host.req_be.next = wstrb[2:0]

    insts += [mux_reg, decode, fsm, outputs]
    return insts
