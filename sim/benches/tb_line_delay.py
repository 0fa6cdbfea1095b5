"""cocotb bench: line_delay against :func:`eyestereo.tools.models.line_delay.line_delay`, bit for bit."""

import cocotb

from eyestereo.sim.lib.bench import StreamTB, run_configured
from eyestereo.tools.models import line_delay as model


class LineDelayTB(StreamTB):
    def expected(self, frame):
        return model.line_delay(frame)


@cocotb.test()
async def line_delay_frames(dut):
    report = await run_configured(dut, LineDelayTB)
    assert report["pixels_compared"] > 0
