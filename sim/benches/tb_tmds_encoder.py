"""cocotb bench: tmds_encoder against :func:`eyestereo.tools.models.tmds_encoder.encode_stream`, every character.

Random inputs: data periods of random length (1 .. ``max_run`` clocks, random bytes, runs of one byte
now and then so that the running disparity is driven to its extremes) between control periods of random
length with random (c0, c1) each clock; the data and control bits that the block must ignore (the byte
during control, c0/c1 during data) are random too. The character after edge k must be the model's for
the inputs before edge k (latency 1), from the first edge after the reset on; during the reset ``q`` is
the control character for (0, 0). Inputs change at the falling edge, ``q`` is read there too.

Config: ``clocks``, ``seed``, ``max_run``.
"""

from __future__ import annotations

import cocotb
import numpy as np
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, FallingEdge

from eyestereo.sim.lib.bench import load_config, write_report
from eyestereo.tools.models.tmds_encoder import CONTROL, encode_stream


def stimulus(rng: np.random.Generator, n: int, max_run: int) -> dict[str, np.ndarray]:
    """Random (data, c0, c1, de) per clock: alternating control and data periods."""
    de = np.zeros(n, dtype=np.int64)
    data = rng.integers(0, 256, n)
    k, on = 0, False
    while k < n:
        run = int(rng.integers(1, max_run + 1))
        if on:
            de[k:k + run] = 1
            if rng.random() < 0.3:  # one byte repeated: the disparity walks to its bounds and back
                data[k:k + run] = rng.integers(0, 256)
        k += run
        on = not on
    return dict(data=data, c0=rng.integers(0, 2, n), c1=rng.integers(0, 2, n), de=de)


class EncoderTB:
    """Clock, reset, the input driver and the output reader."""

    def __init__(self, dut):
        self.dut = dut
        Clock(dut.clk, 40, unit="ns").start()
        for name in ("data", "c0", "c1", "de"):
            getattr(dut, name).value = 0

    async def reset(self) -> None:
        self.dut.rst.value = 1
        await ClockCycles(self.dut.clk, 3)
        await FallingEdge(self.dut.clk)
        assert int(self.dut.q.value) == CONTROL[0], f"q = {self.dut.q.value} during the reset"
        self.dut.rst.value = 0

    async def run(self, stim: dict[str, np.ndarray]) -> np.ndarray:
        """Drive one input per clock (at the falling edge) and read ``q`` one clock later."""
        n = len(stim["de"])
        out = np.empty(n, dtype=np.int64)
        ports = [(getattr(self.dut, k), stim[k].tolist()) for k in ("data", "c0", "c1", "de")]
        for i in range(n + 1):
            if i:
                v = self.dut.q.value
                assert v.is_resolvable, f"q is {v} after edge {i - 1}"
                out[i - 1] = int(v)
            if i < n:
                for port, vals in ports:
                    port.value = vals[i]
            await FallingEdge(self.dut.clk)
        return out


@cocotb.test()
async def encoder_matches_model(dut):
    cfg = load_config()
    rng = np.random.default_rng(int(cfg.get("seed", 1)))
    n = int(cfg.get("clocks", 3000))
    stim = stimulus(rng, n, int(cfg.get("max_run", 40)))
    tb = EncoderTB(dut)
    await tb.reset()
    got = await tb.run(stim)
    want = encode_stream(stim["data"], stim["c0"], stim["c1"], stim["de"])
    bad = np.nonzero(got != want)[0]
    assert not len(bad), (f"{len(bad)} of {n} characters differ, the first after edge {bad[0]}: {got[bad[0]]:#012b}, "
                          f"the model {want[bad[0]]:#012b} (de {stim['de'][bad[0]]}, data {stim['data'][bad[0]]:#04x})")
    write_report(cfg, dict(characters=n, data=int(stim["de"].sum()), control=int(n - stim["de"].sum()),
                           distinct=len(set(got.tolist()))))
