"""uart_rx, uart_tx and uart_bridge: parameter and port checks; the benches on GHDL (marker sim) and on
Icarus and Verilator (MyHDL's Verilog, marker othersims).

* uart_rx: bytes from a sender at the nominal baud and +-3 % off, back to back and with gaps, glitches
  shorter than half a bit on the idle line, framing errors, an overrun; edge for edge with the bit-level
  model, whose bytes must be the bytes sent.
* uart_tx: random bytes offered with random pauses; every line transition at the model's edge, and the
  line decoded by an independent UART receiver gives the bytes back.
* uart_bridge: random request sequences (identify, read and write bursts, unknown bytes, cut-off
  requests, framing errors) against a Python AXI4-Lite slave with random ready delays and SLVERR/DECERR;
  reply bytes, bus accesses and the error count equal the model's; the AXI rules checked on every clock.
"""

import shutil

import pytest
from myhdl import ResetSignal, Signal, intbv

from eyestereo.hdl.interfaces.axil import AxiLite
from eyestereo.hdl.serial.uart_bridge import uart_bridge
from eyestereo.hdl.serial.uart_rx import ByteStream, uart_rx
from eyestereo.hdl.serial.uart_tx import uart_tx
from eyestereo.sim.lib.runner import run_bench

needs_ghdl = pytest.mark.skipif(shutil.which("ghdl") is None, reason="GHDL not installed")
SIMS = [pytest.param("ghdl", marks=needs_ghdl), pytest.param("icarus", marks=pytest.mark.othersims),
        pytest.param("verilator", marks=pytest.mark.othersims)]
PERIOD = 10_000  # ps: 100 MHz


def _clk_rst():
    return Signal(bool(0)), ResetSignal(0, active=1, isasync=False)


def _bridge(**kw):
    kw.setdefault("clocks_per_bit", 33)
    bus = AxiLite(kw.pop("bus_bits", kw.get("addr_bits", 24)))
    return uart_bridge(*_clk_rst(), Signal(bool(1)), Signal(bool(1)), bus, Signal(intbv(0)[16:]), **kw)


@pytest.mark.parametrize("kw,match", [
    (dict(clocks_per_bit=7), r"^uart_bridge: parameter clocks_per_bit=7 is too small: at least 8$"),
    (dict(clocks_per_bit=33.0), r"^uart_bridge: parameter clocks_per_bit must be an integer, got float"),
    (dict(timeout=660), r"^uart_bridge: parameter timeout=660 must be more than 2 byte times \(20 x clocks_per_bit = "
                        r"660 clocks\)"),
    (dict(fifo=1), r"^uart_bridge: parameter fifo=1 is too small: at least 2$"),
    (dict(addr_bits=23, bus_bits=24), r"^uart_bridge: port bus must have 23 address bits"),
    (dict(addr_bits=33, bus_bits=24), r"^uart_bridge: parameter addr_bits=33 is too large: at most 32$"),
])
def test_bridge_parameters_are_checked(kw, match):
    with pytest.raises(ValueError, match=match):
        _bridge(**kw)


def test_bridge_accepts_its_range():
    assert _bridge(timeout=661, fifo=2) is not None
    assert _bridge(clocks_per_bit=868, addr_bits=32) is not None


def test_ports_are_checked():
    clk, rst = _clk_rst()
    with pytest.raises(ValueError, match=r"^uart_rx: port source must be a ByteStream, got ImageStream"):
        from eyestereo.hdl.interfaces.stream import ImageStream
        uart_rx(clk, rst, Signal(bool(1)), ImageStream(8), Signal(bool(0)), Signal(bool(0)), clocks_per_bit=8)
    with pytest.raises(ValueError, match=r"^uart_tx: port tx must be 1 bit wide, got 8"):
        uart_tx(clk, rst, ByteStream(), Signal(intbv(0)[8:]), clocks_per_bit=8)
    with pytest.raises(ValueError, match=r"^uart_bridge: port errors must be 16 bits wide, got 8"):
        uart_bridge(clk, rst, Signal(bool(1)), Signal(bool(1)), AxiLite(24), Signal(intbv(0)[8:]), clocks_per_bit=33)
    line = Signal(bool(1))
    with pytest.raises(ValueError, match=r"^uart_bridge: ports rx and tx share a signal|^uart_bridge: ports tx and rx"):
        uart_bridge(clk, rst, line, line, AxiLite(24), Signal(intbv(0)[16:]), clocks_per_bit=33)


# --------------------------------------------------------------------------------------------------
# benches


@pytest.mark.sim
@pytest.mark.parametrize("sim", SIMS)
@pytest.mark.parametrize("cpb", [8, 13, 33])
def test_uart_rx(request, sim, cpb):
    cfg = dict(period=PERIOD, bytes=24, skews=[0.0, 0.03, -0.03], glitches=12, framing=3, seed=cpb)
    rep = run_bench("uart_rx", "tb_uart_rx", cfg, name=request.node.name, params=dict(clocks_per_bit=cpb), sim=sim)
    assert rep["bytes"] == 3 * 24 + 3 + 1
    assert rep["framing"] == 3
    assert rep["overrun"] == 2


@pytest.mark.sim
@needs_ghdl
def test_uart_rx_115200_baud(request):
    """868 clocks per bit (115200 baud at 100 MHz), a few bytes at each skew."""
    cfg = dict(period=PERIOD, bytes=4, skews=[0.0, 0.03, -0.03], glitches=2, framing=1, seed=5)
    rep = run_bench("uart_rx", "tb_uart_rx", cfg, name=request.node.name, params=dict(clocks_per_bit=868))
    assert rep["bytes"] == 3 * 4 + 1 + 1 and rep["framing"] == 1 and rep["overrun"] == 2


@pytest.mark.sim
@pytest.mark.parametrize("sim", SIMS)
@pytest.mark.parametrize("cpb", [8, 13, 33])
def test_uart_tx(request, sim, cpb):
    cfg = dict(period=PERIOD, bytes=60, seed=cpb)
    rep = run_bench("uart_tx", "tb_uart_tx", cfg, name=request.node.name, params=dict(clocks_per_bit=cpb), sim=sim)
    assert rep["bytes"] == 60
    assert rep["back_to_back"] > 10  # frames with no idle time between them were sent and checked


@pytest.mark.sim
@pytest.mark.parametrize("sim", SIMS)
@pytest.mark.parametrize("cpb,requests,seed", [(8, 120, 1), (33, 40, 2)])
def test_uart_bridge(request, sim, cpb, requests, seed):
    """Random request sequences and the host's SerialBus, on a 24-bit bus with a small FIFO and timeout."""
    params = dict(clocks_per_bit=cpb, addr_bits=24, timeout=40 * cpb + 200, fifo=16)
    cfg = dict(period=PERIOD, requests=requests, seed=seed, long_wait=40 * cpb)
    rep = run_bench("uart_bridge", "tb_uart_bridge", cfg, name=request.node.name, params=params, sim=sim)
    r = rep["random_requests"]
    assert r["accesses"] > requests and r["slverr"] > 0 and r["errors"] > 0
    assert {"identify", "read", "write", "unknown", "pause"} <= set(r["kinds"])
    assert rep["host_driver"]["requests"] == 8
