"""The SRAM word port on the SDRAM's burst port: the arbiter's masters on an SDR SDRAM (``memory="sdram"``)."""

from __future__ import annotations

from myhdl import Signal, always_comb, always_seq, block, concat, intbv

from eyestereo.hdl.common.checks import block_error, check_clock, check_distinct, check_int, check_reset
from eyestereo.hdl.common.fifo import show_ahead_fifo
from eyestereo.hdl.interfaces.sdram_bus import SdramPort
from eyestereo.hdl.interfaces.sram_bus import SramCmd, SramRsp, check_bundle

__all__ = ["sdram_bridge"]


@block
def sdram_bridge(clk, rst, cmd, rsp, port, *, depth: int = 16):
    """Each word command of an :class:`~eyestereo.hdl.interfaces.sram_bus.SramCmd` port as a one-word burst
    on an :class:`~eyestereo.hdl.interfaces.sdram_bus.SdramPort`; read words back on the
    :class:`~eyestereo.hdl.interfaces.sram_bus.SramRsp` port with their tags, in order.

    The SRAM arbiter (:func:`~eyestereo.hdl.memory.sram_arbiter.sram_arbiter`) issues words, not bursts, and takes
    read data whenever it comes (by its tag): so the SDRAM controller behind it serves the same masters. The
    controller keeps each bank's row open, so a master's run of consecutive addresses (the arbiter's turns of 8)
    goes one word per clock; a row change costs its PRECHARGE and ACTIVATE. The word address is the SDRAM's
    (row | bank | column): the SRAM's 1M-word map fits the lower 2^20 words.

    A write's data and byte enables wait in a show-ahead FIFO until the controller pulls them; a read's tag in
    another until its word comes back. The commands wait in two registers: the one the controller reads and a
    skid register that takes a command while the controller holds back the first. So ``cmd.ready`` is a
    flip-flop (the skid register empty, and room in both FIFOs for a word this clock even when none leaves):
    the arbiter's grant logic does not wait for the controller's ``cmd_ready``.

    Ports:
        clk, rst: the memory clock; synchronous active-high reset (let the controller finish or reset it too).
        cmd: SramCmd (slave). rsp: SramRsp (master; no back-pressure). port: SdramPort (master, ``max_burst`` >= 1).

    Parameters:
        depth: entries of each FIFO (writes waiting for their data to be pulled; reads waiting for their word),
            2..64, default 16.

    Latency: a command 1 clock in the bridge's register (2 when the controller held back the one before), then
    the controller's (docs/memory.md: a read on an open row ``CL + 3`` clocks); read words pass straight through.

    Resources: two LUT-RAM FIFOs (18 and ``tag_bits`` bits wide), the command register and the skid register.
    """
    check_clock(clk)
    check_reset(rst)
    check_bundle("cmd", cmd, SramCmd)
    check_bundle("rsp", rsp, SramRsp)
    check_bundle("port", port, SdramPort)
    check_distinct(dict(rsp=rsp, port=port), dict(clk=clk, rst=rst, cmd=cmd))
    depth = check_int("depth", depth, 2, 64)
    if len(cmd.addr) > len(port.cmd_addr):
        raise block_error(f"port cmd has {len(cmd.addr)} address bits, the SDRAM port {len(port.cmd_addr)}")
    if len(cmd.wdata) != len(port.wr_data) or len(cmd.be) != len(port.wr_be):
        raise block_error(f"ports cmd and port differ in data or byte-enable width ({len(cmd.wdata)} / "
                          f"{len(port.wr_data)} bits)")
    if len(rsp.tag) != len(cmd.tag) or len(rsp.data) != len(cmd.wdata):
        raise block_error("ports cmd and rsp differ in tag or data width")

    dw, bw, tw = len(cmd.wdata), len(cmd.be), len(cmd.tag)
    s_valid, s_we = Signal(bool(0)), Signal(bool(0))
    s_addr = Signal(intbv(0)[len(port.cmd_addr):])
    k_valid, k_we = Signal(bool(0)), Signal(bool(0))  # the skid register
    k_addr = Signal(intbv(0)[len(port.cmd_addr):])
    rdy = Signal(bool(0))  # cmd.ready, a register
    take, moved = Signal(bool(0)), Signal(bool(0))
    w_in, w_out = Signal(intbv(0)[dw + bw:]), Signal(intbv(0)[dw + bw:])
    w_push, t_push = Signal(bool(0)), Signal(bool(0))
    w_level = Signal(intbv(0, min=0, max=depth + 1))
    t_level = Signal(intbv(0, min=0, max=depth + 1))
    t_out = Signal(intbv(0)[tw:])
    wfifo = show_ahead_fifo(clk, rst, w_in, w_push, w_out, port.wr_ready, w_level, depth=depth)
    tfifo = show_ahead_fifo(clk, rst, cmd.tag, t_push, t_out, port.rd_valid, t_level, depth=depth)

    @always_comb
    def handshake():
        cmd.ready.next = rdy
        take.next = rdy and cmd.valid
        w_push.next = rdy and cmd.valid and cmd.we
        t_push.next = rdy and cmd.valid and not cmd.we
        w_in.next = concat(cmd.be, cmd.wdata)
        moved.next = not s_valid or port.cmd_ready  # the controller's register is free at the next clock

    @always_seq(clk.posedge, reset=rst)
    def command():
        skid = False
        if moved:
            # the skid register's command first (rdy is low while it is full: no command comes in then)
            s_valid.next = k_valid or take
            k_valid.next = False
            if k_valid:
                s_we.next = k_we
                s_addr.next = k_addr
            else:
                s_we.next = cmd.we
                s_addr.next = cmd.addr
        elif take:
            k_valid.next = True
            k_we.next = cmd.we
            k_addr.next = cmd.addr
            skid = True
        # ready at the next clock: the skid register empty then, and a FIFO below depth - 1 words now (or at
        # depth - 1 with no word coming in), so a word taken at the next clock fits whatever leaves
        w_room = w_level < depth - 1 or (w_level == depth - 1 and not w_push)
        t_room = t_level < depth - 1 or (t_level == depth - 1 and not t_push)
        rdy.next = not (skid or (k_valid and not moved)) and w_room and t_room

    @always_comb
    def to_controller():
        port.cmd_valid.next = s_valid
        port.cmd_we.next = s_we
        port.cmd_addr.next = s_addr
        port.cmd_len.next = 1
        port.wr_data.next = w_out[dw:0]
        port.wr_be.next = w_out[dw + bw:dw]
        rsp.valid.next = port.rd_valid
        rsp.data.next = port.rd_data
        rsp.tag.next = t_out

    return wfifo, tfifo, handshake, command, to_controller
