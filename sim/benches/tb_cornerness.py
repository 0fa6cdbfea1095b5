"""cocotb bench: cornerness against :func:`eyestereo.tools.models.cornerness.cornerness`, bit for bit."""

import cocotb
import numpy as np

from eyestereo.sim.lib.bench import StreamTB, run_configured
from eyestereo.tools.constants import K_CODE_DEFAULT
from eyestereo.tools.models import cornerness as model


class CornernessTB(StreamTB):
    token_spec = "rwindow:99"

    @property
    def k(self) -> int:
        return int(self.cfg.get("k", K_CODE_DEFAULT))

    async def configure(self):
        self.dut.k.value = self.k

    def expected(self, frame):
        return model.to_word(model.cornerness(frame, self.k)), np.ones(frame.shape, dtype=bool)


@cocotb.test()
async def cornerness_frames(dut):
    report = await run_configured(dut, CornernessTB)
    assert report["pixels_compared"] > 0
