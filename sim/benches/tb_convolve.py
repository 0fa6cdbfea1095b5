"""cocotb bench: convolve against :func:`eyestereo.tools.models.convolve.convolve`, bit for bit."""

import cocotb

from eyestereo.sim.lib.bench import StreamTB, run_configured
from eyestereo.tools.models import convolve as model


class ConvolveTB(StreamTB):
    def __init__(self, dut, cfg, **kw):
        super().__init__(dut, cfg, **kw)
        p = cfg["params"]
        self.kernel, _ = model.check_kernel(p.get("kernel"), p.get("col"), p.get("row"))
        self.shift = p.get("shift", 0)
        self.bits, _ = model.output_width(self.kernel, p.get("data_width", 8), self.shift)

    def expected(self, frame):
        values, mask = model.convolve(frame, self.kernel, self.shift)
        return model.to_word(values, self.bits), mask


@cocotb.test()
async def convolve_frames(dut):
    report = await run_configured(dut, ConvolveTB)
    assert report["pixels_compared"] > 0
