"""word_cdc: words into another clock, never torn, in order, settled in time (GHDL); the contract's checker."""

import shutil

import pytest
from myhdl import Signal, intbv

from eyestereo.hdl.streaming.word_cdc import word_cdc
from eyestereo.sim.lib.runner import run_bench
from eyestereo.tools.models.word_cdc import check


def test_the_checker_catches_torn_late_and_early_values():
    d = [(0, 0), (100, 0x12), (200, 0x34)]
    assert check(d, [(150, 0x12), (260, 0x34)], s_period=10, d_period=20, end=1000) == []
    assert check(d, [(150, 0x14)], s_period=10, d_period=20, end=1000)  # a value d never had (torn)
    assert check(d, [(120, 0x12), (260, 0x34)], s_period=10, d_period=20, end=1000)  # too early
    assert check(d, [(260, 0x34), (300, 0x12)], s_period=10, d_period=20, end=1000)  # out of order
    assert check(d, [(150, 0x12)], s_period=10, d_period=20, end=1000)  # never settles on 0x34


@pytest.mark.parametrize("q,match", [(Signal(intbv(0)[8:]), "port q must be a 16-bit Signal like d, got 8 bits"),
                                     (Signal(bool(0)), "port q must be a 16-bit Signal like d, got a Signal")])
def test_ports_are_checked(q, match):
    with pytest.raises(ValueError, match=rf"^word_cdc: {match}"):
        word_cdc(Signal(bool(0)), Signal(intbv(0)[16:]), Signal(bool(0)), q)
    with pytest.raises(ValueError, match=r"^word_cdc: port d must be a Signal\(intbv"):
        word_cdc(Signal(bool(0)), Signal(bool(0)), Signal(bool(0)), Signal(bool(0)))


@pytest.mark.sim
@pytest.mark.skipif(shutil.which("ghdl") is None, reason="GHDL not installed")
@pytest.mark.parametrize("sclk,dclk", [((10000, 0), (20000, 3300)), ((20000, 0), (10000, 7100))],
                         ids=["100to50", "50to100"])
def test_words_cross(request, sclk, dclk):
    cfg = dict(sclk=list(sclk), dclk=list(dclk), changes=300, seed=len(request.node.name))
    rep = run_bench("word_cdc", "tb_word_cdc", cfg, name=request.node.name, params=dict(width=16))
    assert rep["q_changes"] > 50
