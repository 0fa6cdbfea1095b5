"""Hold a fetch port's requests back while a consumer further down has no room (the dense option's pacing)."""

from __future__ import annotations

from myhdl import Signal, always_comb, always_seq, block

from eyestereo.hdl.common.checks import block_error, check_clock, check_distinct, check_reset, check_signal
from eyestereo.hdl.interfaces.fetch_port import check_fetch

__all__ = ["fetch_gate"]


@block
def fetch_gate(clk, rst, up, down, hold):
    """Pass a pixel fetch port through, but no new request while ``hold`` is high.

    The rectifier (``up``) asks, the memory side (``down``) answers; every request and every response passes
    unchanged, except that a request is not offered downstream (and not taken upstream) while the gate is
    shut. The gate follows ``hold`` through a register that changes only while no request waits
    downstream, so a request once offered stays offered until it moves (the fetch port's rule): after
    ``hold`` rises, at most the request waiting then still moves. Responses of requests already made keep
    coming (the rectifier's stream stops after at most its ``depth`` sides in flight).

    Timing (``#`` high, ``_`` low; ``v``/``r``: ``down``'s req_valid/req_ready)::

        cycle        0    1    2    3    4    5
        hold         _    #    #    #    _    _
        gate (reg)   _    _    #    #    #    _
        up.valid     #    #    #    #    #    #
        down.valid   #    #    _    _    _    #
        down.ready   _    #    #    #    #    #     the request of cycle 0 waits, moves in cycle 1

    Ports:
        clk, rst: clock and synchronous reset (the gate open).
        up: :class:`~eyestereo.hdl.interfaces.fetch_port.FetchPort` from the rectifier (its requests in, the
            responses out).
        down: FetchPort to the memory side (the same geometry).
        hold: in, 1 bit: shut the gate (the consumer's room is short).

    Parameters: none.

    Latency: 0 (requests and responses pass combinationally); the gate shuts a clock after ``hold`` rises
    (later while a request waits) and opens a clock after it falls.

    Resources: one flip-flop and a few LUTs.
    """
    check_clock(clk)
    check_reset(rst)
    check_fetch("up", up)
    check_fetch("down", down)
    check_signal("hold", hold, width=1)
    check_distinct(dict(down=down), dict(clk=clk, rst=rst, up=up, hold=hold))
    if (up.width, up.height) != (down.width, down.height):
        raise block_error(f"port down is {down.width}x{down.height}, port up {up.width}x{up.height}: one geometry")
    gate = Signal(bool(0))

    @always_seq(clk.posedge, reset=rst)
    def follow():
        # a request offered downstream and not yet taken keeps the gate as it is
        if not (down.req_valid and not down.req_ready):
            gate.next = hold

    @always_comb
    def requests():
        down.req_valid.next = up.req_valid and not gate
        up.req_ready.next = down.req_ready and not gate
        down.req_x.next = up.req_x
        down.req_y.next = up.req_y
        down.req_cam.next = up.req_cam
        down.req_mask.next = up.req_mask

    @always_comb
    def responses():
        up.rsp_valid.next = down.rsp_valid
        up.rsp_idx.next = down.rsp_idx
        up.rsp_data.next = down.rsp_data

    return follow, requests, responses
