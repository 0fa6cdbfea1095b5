"""cocotb bench: harris_window against :func:`eyestereo.tools.models.harris_window.harris_window`, bit for bit."""

import cocotb

from eyestereo.sim.lib.bench import StreamTB, run_configured
from eyestereo.tools.models import harris_window as model


class HarrisWindowTB(StreamTB):
    token_spec = "grad:99:128"

    def expected(self, frame):
        return model.harris_window(frame)


@cocotb.test()
async def harris_window_frames(dut):
    report = await run_configured(dut, HarrisWindowTB)
    assert report["pixels_compared"] > 0
