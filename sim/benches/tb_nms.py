"""cocotb bench: nms against :func:`eyestereo.tools.models.nms.nms`, bit for bit."""

import cocotb

from eyestereo.sim.lib.bench import StreamTB, run_configured
from eyestereo.tools.constants import NMS_DEFAULT
from eyestereo.tools.models import cornerness as corner_model
from eyestereo.tools.models import nms as model


class NmsTB(StreamTB):
    token_spec = "rcorner:99:-3:3"

    def expected(self, frame):
        return model.nms(corner_model.from_word(frame), self.cfg["params"].get("size", NMS_DEFAULT))


@cocotb.test()
async def nms_frames(dut):
    report = await run_configured(dut, NmsTB)
    assert report["pixels_compared"] > 0
