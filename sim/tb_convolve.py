"""cocotb bench: convolve against :func:`eyestereo.tools.convolve.convolve`, bit for bit."""

import cocotb

from eyestereo.sim.bench import StreamTB, frames_from_config, load_config, run_scenario, write_report
from eyestereo.tools import convolve as model


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
    cfg = load_config()
    p = cfg["params"]
    w, h, bits = p.get("width", 352), p.get("height", 288), p.get("data_width", 8)
    tb = ConvolveTB(dut, cfg, out_width=w, out_height=h)
    frames = frames_from_config(cfg, w, h, bits)
    report = await run_scenario(tb, frames, token_after=cfg.get("token_after"),
                                token_frame=frames_from_config(dict(frames=["random:99"]), w, h, bits)[0])
    write_report(cfg, report)
