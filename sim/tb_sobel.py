"""cocotb bench: sobel against :func:`eyestereo.tools.sobel.sobel`, bit for bit."""

import cocotb

from eyestereo.sim.bench import StreamTB, frames_from_config, load_config, run_scenario, write_report
from eyestereo.tools import sobel as model


class SobelTB(StreamTB):
    def expected(self, frame):
        ix, iy, mask = model.sobel(frame)
        return model.pack(ix, iy), mask


@cocotb.test()
async def sobel_frames(dut):
    cfg = load_config()
    w, h = cfg["params"].get("width", 352), cfg["params"].get("height", 288)
    tb = SobelTB(dut, cfg, out_width=w, out_height=h)
    frames = frames_from_config(cfg, w, h)
    token_after = cfg.get("token_after")
    report = await run_scenario(tb, frames, token_after=token_after,
                                token_frame=frames_from_config(dict(frames=["random:99"]), w, h)[0])
    write_report(cfg, report)
