"""The board's own registers (:data:`eyestereo.tools.board.regmap.BOARD_REGMAP`) on an AXI4-Lite slave."""

from __future__ import annotations

from myhdl import Signal, always_comb, always_seq, block, concat, intbv

from eyestereo.hdl.common.checks import block_error, check_clock, check_int, check_reset, check_signal
from eyestereo.hdl.interfaces.axil import check_axil
from eyestereo.tools.board.regmap import BOARD_REGMAP

__all__ = ["board_regs"]

OKAY, SLVERR = 0, 2


@block
def board_regs(clk, rst, bus, display_run, sccb_restart, pll_locked, sccb_busy, display_idle, cam_present, copies,
               uart_errors, *,
               mem_mhz: int = 100, harris_mhz: int = 50, pixel_mhz: int = 25, tmds_mhz: int = 125):
    """The board's registers (docs/boards.md's table, from :data:`~eyestereo.tools.board.regmap.BOARD_REGMAP`):
    identification, the display's run bit, the cameras' restart, the board's status, the link's errors, the clocks.

    Bus behaviour as the front end's register bank (docs/registers.md): the low two address bits ignored,
    byte strobes honoured on BOARD_CTRL, SLVERR (read data 0) for an unmapped word and for a write to a const or
    status register; one access at a time, a write first when both wait.

    Ports:
        clk, rst: the bus clock and its synchronous reset (BOARD_CTRL to its reset value).
        bus: :class:`~eyestereo.hdl.interfaces.axil.AxiLite` slave; only the low 5 address bits are decoded (the
            board's bridge reaches it at bus address bit 23: the address splitter in front of it).
        display_run: BOARD_CTRL.display_run (out).
        sccb_restart: BOARD_CMD.sccb_restart (out, one clock per 1 written).
        pll_locked, sccb_busy, display_idle (1 bit), cam_present (2 bits), copies (16 bits), uart_errors (16 bits):
            the status inputs, in this clock (synchronise them before).

    Parameters:
        mem_mhz, harris_mhz, pixel_mhz, tmds_mhz: BOARD_CLOCKS's constants (1..255).

    Latency: ``awready``/``wready`` (or ``arready``) in the clock after the valids, the response in the clock after
    the address moved.

    Resources: about 60 LUTs and 60 flip-flops.
    """
    check_clock(clk)
    check_reset(rst)
    for name, v in (("mem_mhz", mem_mhz), ("harris_mhz", harris_mhz), ("pixel_mhz", pixel_mhz),
                    ("tmds_mhz", tmds_mhz)):
        check_int(name, v, 1, 255)
    abits = len(bus.araddr)
    if abits < BOARD_REGMAP.addr_bits:
        raise block_error(f"bus needs at least {BOARD_REGMAP.addr_bits} address bits, has {abits}")
    check_axil("bus", bus, addr_bits=abits)
    for name, s, w in (("display_run", display_run, 1), ("sccb_restart", sccb_restart, 1),
                       ("pll_locked", pll_locked, 1), ("sccb_busy", sccb_busy, 1), ("display_idle", display_idle, 1),
                       ("cam_present", cam_present, 2),
                       ("copies", copies, 16), ("uart_errors", uart_errors, 16)):
        check_signal(name, s, width=w)

    R = BOARD_REGMAP
    a_id, a_ctrl, a_cmd, a_status, a_err, a_clk = (R[n].offset >> 2 for n in (
        "BOARD_ID", "BOARD_CTRL", "BOARD_CMD", "BOARD_STATUS", "BOARD_ERRORS", "BOARD_CLOCKS"))
    id_value = R["BOARD_ID"].reset_value()
    clocks_value = R["BOARD_CLOCKS"].reset_value(dict(mem_mhz=mem_mhz, harris_mhz=harris_mhz, pixel_mhz=pixel_mhz,
                                                      tmds_mhz=tmds_mhz))
    run_reset = R["BOARD_CTRL"].reset_value()

    run = Signal(bool(run_reset & 1))
    busy = Signal(bool(0))  # an access is being answered
    status = Signal(intbv(0)[32:])

    @always_comb
    def status_word():
        status.next = concat(copies, intbv(0)[11:], display_idle, cam_present, sccb_busy, pll_locked)

    @always_comb
    def outs():
        display_run.next = run

    wword = Signal(intbv(0)[BOARD_REGMAP.addr_bits - 2:])
    rword = Signal(intbv(0)[BOARD_REGMAP.addr_bits - 2:])
    wdat = Signal(bool(0))
    wstb = Signal(bool(0))

    aw_r, w_r, ar_r, b_v, r_v = (Signal(bool(0)) for _ in range(5))

    @always_comb
    def handshake():
        # the slave's readies and valids from registers of their own (VHDL-93 cannot read an output port)
        bus.awready.next = aw_r
        bus.wready.next = w_r
        bus.arready.next = ar_r
        bus.bvalid.next = b_v
        bus.rvalid.next = r_v

    @always_seq(clk.posedge, reset=rst)
    def serve():
        sccb_restart.next = 0
        if b_v and bus.bready:
            b_v.next = 0
            busy.next = 0
        if r_v and bus.rready:
            r_v.next = 0
            busy.next = 0
        if aw_r:
            # the write's address and data move at this edge: act, answer from the next clock
            aw_r.next = 0
            w_r.next = 0
            b_v.next = 1
            bus.bresp.next = SLVERR
            if wword == a_ctrl:
                bus.bresp.next = OKAY
                if wstb:
                    run.next = wdat
            elif wword == a_cmd:
                bus.bresp.next = OKAY
                if wstb and wdat:
                    sccb_restart.next = 1
        elif ar_r:
            ar_r.next = 0
            r_v.next = 1
            bus.rresp.next = OKAY
            bus.rdata.next = 0
            if rword == a_id:
                bus.rdata.next = id_value
            elif rword == a_ctrl:
                bus.rdata.next = run
            elif rword == a_cmd:
                bus.rdata.next = 0
            elif rword == a_status:
                bus.rdata.next = status
            elif rword == a_err:
                bus.rdata.next = uart_errors
            elif rword == a_clk:
                bus.rdata.next = clocks_value
            else:
                bus.rresp.next = SLVERR
        elif not busy:
            if bus.awvalid and bus.wvalid:
                aw_r.next = 1
                w_r.next = 1
                busy.next = 1
                wword.next = bus.awaddr[BOARD_REGMAP.addr_bits:2]
                wdat.next = bus.wdata[0]
                wstb.next = bus.wstrb[0]
            elif bus.arvalid:
                ar_r.next = 1
                busy.next = 1
                rword.next = bus.araddr[BOARD_REGMAP.addr_bits:2]

    return status_word, outs, handshake, serve
