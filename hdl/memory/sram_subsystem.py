"""The SRAM subsystem: arbiter and controller together, the SRAM's pins on one side, the six masters on the other."""

from myhdl import block

from eyestereo.hdl.common.checks import check_choice, check_distinct, check_int
from eyestereo.hdl.memory.sram_arbiter import TAG_BITS, check_masters, sram_arbiter
from eyestereo.hdl.interfaces.sram_bus import SramCmd, SramPins, SramRsp, check_bundle
from eyestereo.hdl.memory.sram_controller import sram_controller
from eyestereo.tools.sram import KINDS


@block
def sram_subsystem(clk, rst, cam0, cam1, fetch, rect, feat, host, ctl, stat, sram, *, kind: str = "nobl",
                   read_latency: int = 2, width: int = 352, height: int = 288, feature_words: int = 8192,
                   depth: int = 16, burst: int = 8, fetch_burst: int = 8, host_burst: int = 1,
                   counter_bits: int = 32, cameras: bool = True):
    """:func:`~eyestereo.hdl.memory.sram_arbiter.sram_arbiter` on
    :func:`~eyestereo.hdl.memory.sram_controller.sram_controller`.

    What the complete system instantiates: the masters' ports as the arbiter documents them, the frame
    handshake, the status port, and the SRAM's pins (:class:`~eyestereo.hdl.interfaces.sram_bus.SramPins`).

    Ports:
        clk, rst, cam0, cam1, fetch, rect, feat, host, ctl, stat: as :func:`sram_arbiter`.
        sram: :class:`~eyestereo.hdl.interfaces.sram_bus.SramPins`.

    Parameters:
        kind, read_latency: the part (:func:`sram_controller`).
        width, height, feature_words, depth, burst, fetch_burst, host_burst, counter_bits, cameras: as
            :func:`sram_arbiter`.

    Latency: as :func:`sram_arbiter` (measured with a part of read latency 2: fetch 11 clocks to the
    first pixel, host reads 7 clocks, on a quiet bus).

    Resources: see docs/sram.md.
    """
    # every check here, so that a message names this block (not the arbiter or controller inside)
    check_masters(clk, rst, cam0, cam1, fetch, rect, feat, host, ctl, stat, width=width, height=height,
                  feature_words=feature_words, depth=depth, burst=burst, fetch_burst=fetch_burst,
                  host_burst=host_burst, counter_bits=counter_bits, cameras=cameras)
    check_bundle("sram", sram, SramPins)
    check_distinct(dict(fetch=fetch, stat=stat, sram=sram), dict(clk=clk, rst=rst, cam0=cam0, cam1=cam1, rect=rect,
                                                               feat=feat, host=host, ctl=ctl))
    kind = check_choice("kind", kind, KINDS)
    read_latency = check_int("read_latency", read_latency, 1, 3)
    cmd = SramCmd(tag_bits=TAG_BITS)
    rsp = SramRsp(tag_bits=TAG_BITS)
    arb = sram_arbiter(clk, rst, cam0, cam1, fetch, rect, feat, host, ctl, stat, cmd, rsp, width=width,
                       height=height, feature_words=feature_words, depth=depth, burst=burst,
                       fetch_burst=fetch_burst, host_burst=host_burst, counter_bits=counter_bits, cameras=cameras)
    ctrl = sram_controller(clk, rst, cmd, rsp, sram, kind=kind, read_latency=read_latency)
    return arb, ctrl
