"""cocotb bench: sobel against :func:`eyestereo.tools.models.sobel.sobel`, bit for bit."""

import cocotb

from eyestereo.sim.lib.bench import StreamTB, run_configured
from eyestereo.tools.models import sobel as model


class SobelTB(StreamTB):
    def expected(self, frame):
        ix, iy, mask = model.sobel(frame)
        return model.pack(ix, iy), mask


@cocotb.test()
async def sobel_frames(dut):
    report = await run_configured(dut, SobelTB)
    assert report["pixels_compared"] > 0
