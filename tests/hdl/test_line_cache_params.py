"""Parameter and port checks of line_cache, stream_rectifier and the front end's rectify option (issue 26)."""

import pytest
from myhdl import ResetSignal, Signal

from eyestereo.hdl.interfaces.fetch_port import FetchPort
from eyestereo.hdl.interfaces.queue import QueuePort
from eyestereo.hdl.interfaces.stream import ImageStream
from eyestereo.hdl.rectify.line_cache import line_cache
from eyestereo.hdl.rectify.stream_rectifier import stream_rectifier
from eyestereo.tools.camera import WORD


def cache_ports(w=32, h=24):
    return (Signal(bool(0)), ResetSignal(0, active=1, isasync=False), QueuePort(WORD), QueuePort(WORD),
            FetchPort(w, h), Signal(bool(0)), Signal(bool(0)), Signal(bool(0)), Signal(bool(0)), Signal(bool(0)))


@pytest.mark.parametrize("kw,msg", [
    (dict(lines=12), "power of two"),
    (dict(lines=32), "more lines than the frame"),
    (dict(lines=1), "lines"),
    (dict(width=40), "sized for 32x24"),
])
def test_line_cache_refuses(kw, msg):
    params = dict(width=32, height=24, lines=8)
    params.update(kw)
    with pytest.raises(ValueError, match=msg):
        line_cache(*cache_ports(), **params)


def test_line_cache_refuses_a_shared_output():
    p = list(cache_ports())
    p[9] = p[8]  # overrun = begun
    with pytest.raises(ValueError, match="share a signal"):
        line_cache(*p, width=32, height=24, lines=8)


def stream_ports():
    b = lambda: Signal(bool(0))  # noqa: E731
    return (b(), ResetSignal(0, active=1, isasync=False), QueuePort(WORD), QueuePort(WORD),
            ImageStream(8, stereo=True), b(), b(), b(), b(), b())


def test_stream_rectifier_refuses_a_cache_the_calibration_outgrows():
    with pytest.raises(ValueError, match="power of two"):
        stream_rectifier(*stream_ports(), quantizers="rig:32x24", lines=24)
    with pytest.raises(ValueError, match="lines"):
        stream_rectifier(*stream_ports(), quantizers="rig:32x24", lines=128)


def test_stream_rectifier_refuses_a_mono_source():
    p = list(stream_ports())
    p[4] = ImageStream(8)
    with pytest.raises(ValueError, match="source"):
        stream_rectifier(*p, quantizers="rig:32x24")


def test_frontend_rectify_choice():
    from eyestereo.hdl.flow.catalog import get

    spec = get("stereo_frontend")
    with pytest.raises(ValueError, match="rectify"):
        spec.elaborate(quantizers="rig:32x24", rectify="cache")
    with pytest.raises(ValueError, match="cache_lines is for rectify='stream'"):
        spec.elaborate(quantizers="rig:32x24", cache_lines=8)


def test_frontend_memory_choice():
    from eyestereo.hdl.flow.catalog import get
    from eyestereo.hdl.interfaces.sdram_bus import SdramPins
    from eyestereo.hdl.interfaces.sram_bus import SramPins

    spec = get("stereo_frontend")
    with pytest.raises(ValueError, match="memory"):
        spec.elaborate(quantizers="rig:32x24", memory="ddr3")
    # the pins must be the memory's: SramPins for an SDRAM is refused, and the reverse
    ports, kw, _ = spec.ports(quantizers="rig:32x24", memory="sdram")
    ports["sram"] = SramPins()
    with pytest.raises(ValueError, match="sram"):
        spec.func(*ports.values(), **kw)
    ports, kw, _ = spec.ports(quantizers="rig:32x24")
    ports["sram"] = SdramPins()
    with pytest.raises(ValueError, match="sram"):
        spec.func(*ports.values(), **kw)
