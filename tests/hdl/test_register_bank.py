"""GHDL regression of the register bank through the AXI4-Lite bus model, checked against the register table."""

import shutil

import pytest

from eyestereo.sim.runner import run_bench

pytestmark = [pytest.mark.sim, pytest.mark.skipif(shutil.which("ghdl") is None, reason="GHDL not installed")]


def test_register_bank_against_table(request):
    rep = run_bench("register_bank", "tb_register_bank", dict(seed=3, pause=0.3), name=request.node.name,
                    params=dict(width=64, height=48))
    assert rep["counts"]["ar"] > 300 and rep["gaps"] > 100
    assert rep["host_requests"] > 30
