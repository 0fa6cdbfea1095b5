"""cocotb bench: prethreshold against :func:`eyestereo.tools.models.prethreshold.prethreshold`, bit for bit.

The config's ``thresholds`` (a dict block index -> code) are written through the register port after
reset; blocks not written must act as threshold 0. With ``reset_after_write`` a second ``rst`` pulse
follows the writes, after which every threshold must read 0 again.
"""

import cocotb
import numpy as np

from eyestereo.sim.lib.bench import StreamTB, run_configured, write_thresholds
from eyestereo.tools.constants import THRESHOLD_BLOCKS
from eyestereo.tools.models import cornerness as corner_model
from eyestereo.tools.models import prethreshold as model


class PrethresholdTB(StreamTB):
    token_spec = "rcorner:99:-100:100"

    def __init__(self, dut, cfg, **kw):
        super().__init__(dut, cfg, **kw)
        p = cfg["params"]
        self.blocks = tuple(p.get("blocks", THRESHOLD_BLOCKS))
        n = self.blocks[0] * self.blocks[1]
        self.written = {int(i): int(v) for i, v in cfg.get("thresholds", {}).items()}
        if cfg.get("reset_after_write"):
            self.effective = [0] * n
        else:
            self.effective = [self.written.get(i, 0) for i in range(n)]
        dut.thr_we.value = 0
        dut.thr_addr.value = 0
        dut.thr_data.value = 0

    async def configure(self):
        await write_thresholds(self.dut, self.clk, self.written, corner_model.OUT.wl)
        if self.cfg.get("reset_after_write"):
            await self.reset()

    def expected(self, frame):
        values = corner_model.from_word(frame)
        out = model.prethreshold(values, self.effective, self.blocks)
        return corner_model.to_word(out), np.ones(frame.shape, dtype=bool)


@cocotb.test()
async def prethreshold_frames(dut):
    report = await run_configured(dut, PrethresholdTB)
    assert report["pixels_compared"] > 0
