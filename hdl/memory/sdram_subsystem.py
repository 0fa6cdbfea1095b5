"""The SDRAM subsystem: the SRAM arbiter's six masters on an SDR SDRAM (``memory="sdram"``)."""

from myhdl import always_seq, block

from eyestereo.hdl.common.checks import block_error, check_distinct, check_int, check_signal
from eyestereo.hdl.interfaces.sdram_bus import SdramPins, SdramPort
from eyestereo.hdl.interfaces.sram_bus import SramCmd, SramRsp, check_bundle
from eyestereo.hdl.memory.sdram_bridge import sdram_bridge
from eyestereo.hdl.memory.sdram_controller import sdram_controller
from eyestereo.hdl.memory.sram_arbiter import TAG_BITS, check_masters, sram_arbiter
from eyestereo.tools.sdram import ULX3S
from eyestereo.tools.sdram import part as sdram_part

__all__ = ["sdram_subsystem"]


@block
def sdram_subsystem(clk, rst, cam0, cam1, fetch, rect, feat, host, ctl, stat, sdram, ready=None, *,
                    part: str = ULX3S, clock_mhz: float = 100.0, cas_latency: int = 2, width: int = 352,
                    height: int = 288,
                    feature_words: int = 8192, depth: int = 16, burst: int = 8, fetch_burst: int = 8,
                    host_burst: int = 1, counter_bits: int = 32, cameras: bool = True):
    """The arbiter's six masters on an SDRAM: :func:`~eyestereo.hdl.memory.sram_arbiter.sram_arbiter` ->
    :func:`~eyestereo.hdl.memory.sdram_bridge.sdram_bridge` ->
    :func:`~eyestereo.hdl.memory.sdram_controller.sdram_controller`: the same masters, frame handshake, status
    port and address map as :func:`~eyestereo.hdl.memory.sram_subsystem.sram_subsystem`, on an SDRAM's pins.

    The arbiter's word accesses become one-word bursts; the controller keeps each bank's row open, so the masters'
    runs of consecutive words (camera lines, the rectified writer, the host's reads) go at a word per clock and a
    row change (every 1024 words on the ULX3S's part) costs its PRECHARGE and ACTIVATE; refreshes take their
    share (docs/memory.md). The 2x2 fetches of ``rectify="fetch"`` jump between rows and go much slower than on
    the SRAM: the front end pairs the SDRAM with ``rectify="stream"``.

    Ports:
        clk, rst, cam0, cam1, fetch, rect, feat, host, ctl, stat: as :func:`sram_arbiter`.
        sdram: :class:`~eyestereo.hdl.interfaces.sdram_bus.SdramPins` of ``part``.
        ready: optional output, 1 bit: the SDRAM has been through its power-up sequence (from the controller's
            first ``cmd_ready``; 200 us and more after reset: a master's words before it wait, and a stream
            writer's overflow; the front end starts no frame before it).

    Parameters:
        part, clock_mhz, cas_latency: the SDRAM part and its clock (:func:`sdram_controller`).
        width, height, feature_words, depth, burst, fetch_burst, host_burst, counter_bits, cameras: as
            :func:`sram_arbiter`.

    Latency: the arbiter's and the controller's: a host read on an open row about 5 clocks more than on the SRAM.

    Resources: the arbiter's, the bridge's two LUT-RAM FIFOs and the controller's (docs/memory.md).
    """
    check_masters(clk, rst, cam0, cam1, fetch, rect, feat, host, ctl, stat, width=width, height=height,
                  feature_words=feature_words, depth=depth, burst=burst, fetch_burst=fetch_burst,
                  host_burst=host_burst, counter_bits=counter_bits, cameras=cameras)
    check_bundle("sdram", sdram, SdramPins)
    outs = dict(fetch=fetch, stat=stat, sdram=sdram)
    if ready is not None:
        check_signal("ready", ready, width=1)
        outs["ready"] = ready
    check_distinct(outs, dict(clk=clk, rst=rst, cam0=cam0, cam1=cam1, rect=rect,
                                                                 feat=feat, host=host, ctl=ctl))
    try:
        p = sdram_part(part)
    except ValueError as e:
        raise block_error(f"parameter part: {e}") from None
    cas_latency = check_int("cas_latency", cas_latency, 2, 3)
    cmd = SramCmd(tag_bits=TAG_BITS)
    rsp = SramRsp(tag_bits=TAG_BITS)
    port = SdramPort(p.addr_bits, 1, p.data_bits)
    arb = sram_arbiter(clk, rst, cam0, cam1, fetch, rect, feat, host, ctl, stat, cmd, rsp, width=width,
                       height=height, feature_words=feature_words, depth=depth, burst=burst,
                       fetch_burst=fetch_burst, host_burst=host_burst, counter_bits=counter_bits, cameras=cameras)
    bridge = sdram_bridge(clk, rst, cmd, rsp, port)
    ctrl = sdram_controller(clk, rst, port, sdram, part=part, clock_mhz=clock_mhz, cas_latency=cas_latency,
                            max_burst=1)
    insts = [arb, bridge, ctrl]
    if ready is not None:
        @always_seq(clk.posedge, reset=rst)
        def init_done():
            if port.cmd_ready:
                ready.next = True

        insts.append(init_done)
    return insts
