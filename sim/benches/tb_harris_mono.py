"""cocotb bench: harris_mono against :func:`eyestereo.tools.models.harris_mono.harris_mono`, bit for bit."""

import cocotb

from eyestereo.sim.lib.bench import StreamTB, run_configured, write_thresholds
from eyestereo.tools.constants import K_CODE_DEFAULT, NMS_DEFAULT, THRESHOLD_BLOCKS
from eyestereo.tools.models import cornerness as corner_model
from eyestereo.tools.models import harris_mono as model


class HarrisMonoTB(StreamTB):
    def __init__(self, dut, cfg, **kw):
        super().__init__(dut, cfg, **kw)
        p = cfg["params"]
        self.blocks = tuple(p.get("blocks", THRESHOLD_BLOCKS))
        self.nms = p.get("nms", NMS_DEFAULT)
        self.k = int(cfg.get("k", K_CODE_DEFAULT))
        n = self.blocks[0] * self.blocks[1]
        thr = cfg.get("thresholds", [0] * n)
        self.thresholds = [int(t) for t in (thr if isinstance(thr, list) else [thr] * n)]
        dut.thr_we.value = 0
        dut.k.value = 0

    async def configure(self):
        self.dut.k.value = self.k
        await write_thresholds(self.dut, self.clk, dict(enumerate(self.thresholds)), corner_model.OUT.wl)

    def expected(self, frame):
        return model.harris_mono(frame, self.k, self.thresholds, blocks=self.blocks, nms=self.nms)


@cocotb.test()
async def harris_mono_frames(dut):
    report = await run_configured(dut, HarrisMonoTB)
    assert report["pixels_compared"] > 0
