"""stream_cdc: stereo frames from the memory clock into the Harris clock on GHDL, against its model."""

import random
import shutil

import pytest

from eyestereo.sim.lib.runner import run_bench
from eyestereo.tools.models.stream_cdc import pack, unpack

needs_ghdl = pytest.mark.skipif(shutil.which("ghdl") is None, reason="GHDL not installed")


def test_pack_keeps_the_last_pair_together():
    # the left beat of the last pixel carries eol/eof in its word, not to the FIFO's frame logic
    word, eol, eof = pack((0xAB, True, True, 0), 8, True)
    assert (eol, eof) == (False, False) and word == 0xAB | 0b110 << 8
    assert pack((0xCD, True, True, 1), 8, True) == (0xCD | 0b111 << 8, True, True)
    assert pack((0, False, True, 0), 8, True)[1:] == (False, True)  # a token stays a token
    rng = random.Random(1)
    for _ in range(200):
        b = (rng.randrange(256), rng.random() < 0.5, rng.random() < 0.3, rng.random() < 0.5)
        if b[2] and not b[1]:
            assert unpack(*pack(b, 8, True), 8, True)[1:3] == (False, True)
        else:
            assert unpack(*pack(b, 8, True), 8, True) == b


def _run(request, cfg, **params):
    return run_bench("stream_cdc", "tb_stream_cdc", cfg, name=request.node.name,
                     params=dict(dict(data_width=8, stereo=True, depth=16), **params))


@needs_ghdl
@pytest.mark.sim
@pytest.mark.parametrize("rclk,seed", [((20000, 7300), 1), ((10000, 3700), 2)], ids=["100to50", "100to100"])
def test_stereo_frames_cross_bit_exact(request, rclk, seed):
    """The rectifier's pace (a pair every 4 memory clocks) into 50 MHz and into 100 MHz of another phase."""
    rep = _run(request, dict(wclk=[10000, 0], rclk=list(rclk), width=16, height=6, frames=3, pair_clocks=4,
                             gap=40, seed=seed))
    assert rep["frames"] == rep["sent"] == 3 and rep["dropped"] == 0 and rep["tokens"] == 0
    assert rep["max_level"] <= 8


@needs_ghdl
@pytest.mark.sim
def test_overflow_cuts_frames_with_tokens(request):
    """Twice the Harris side's rate (one beat per memory clock): every frame overflows the 16 entries,
    is cut with a reset token and counted (frames of 64 beats; the FIFO drains in the gaps)."""
    rep = _run(request, dict(wclk=[10000, 0], rclk=[20000, 5100], width=8, height=4, frames=3, duty=1.0,
                             gap=300, seed=4))
    assert rep["dropped"] == 3 and rep["tokens"] == 3 and rep["frames"] == 0


@needs_ghdl
@pytest.mark.sim
def test_mono_stream_and_a_token(request):
    rep = _run(request, dict(wclk=[10000, 0], rclk=[20000, 1234], width=8, height=4, frames=3, duty=0.4,
                             tokens={1: 21}, seed=5), stereo=False)
    assert rep["frames"] == rep["sent"] == 2 and rep["tokens"] == 1


# ---- elaboration checks ------------------------------------------------------------------------------
from myhdl import Signal, intbv  # noqa: E402

from eyestereo.hdl.flow.catalog import BLOCKS  # noqa: E402
from eyestereo.hdl.interfaces.stream import ImageStream  # noqa: E402
from eyestereo.hdl.streaming.stream_cdc import stream_cdc  # noqa: E402


@pytest.mark.parametrize("over,kw,match", [
    (dict(source=ImageStream(8)), {}, r"port source must be a stereo stream"),
    (dict(source=ImageStream(9, stereo=True)), {}, r"port source must carry 8-bit data"),
    (dict(sink=None), {}, r"port sink must be an ImageStream, got None"),
    (dict(dropped=Signal(intbv(0)[8:])), {}, r"port dropped must be 16 bits wide"),
    (dict(rclk=None), {}, r"port rclk must be a 1-bit Signal"),
    ({}, dict(depth=12), r"parameter depth=12 must be a power of two"),
    ({}, dict(depth=2), r"parameter depth=2 is too small"),
])
def test_stream_cdc_refuses(over, kw, match):
    ports = BLOCKS["stream_cdc"].ports()[0]
    ports.update(over)
    with pytest.raises(ValueError, match=rf"^stream_cdc: {match}"):
        stream_cdc(*ports.values(), **kw)


def test_stream_cdc_source_needs_its_own_signals():
    ports = BLOCKS["stream_cdc"].ports()[0]
    ports["source"] = ports["sink"]
    with pytest.raises(ValueError, match=r"^stream_cdc: ports source and sink share a signal"):
        stream_cdc(*ports.values())


@needs_ghdl
@pytest.mark.sim
def test_register_write_port_crosses_as_one_beat_frames(request):
    """The threshold write port (4-bit index and 20-bit code) from the bus clock into the Harris clock:
    each write a 1x1 frame of 24 bits; a write every 4 bus clocks at most (the bank's pace) never drops."""
    rep = _run(request, dict(wclk=[10000, 0], rclk=[20000, 8900], width=1, height=1, frames=32, duty=0.25,
                             seed=6), stereo=False, data_width=24)
    assert rep["frames"] == rep["sent"] == 32 and rep["dropped"] == 0
