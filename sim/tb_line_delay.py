"""cocotb bench: line_delay against :func:`eyestereo.tools.line_delay.line_delay`, bit for bit."""

import cocotb

from eyestereo.sim.bench import StreamTB, frames_from_config, load_config, run_scenario, write_report
from eyestereo.tools import line_delay as model


class LineDelayTB(StreamTB):
    def expected(self, frame):
        return model.line_delay(frame)


@cocotb.test()
async def line_delay_frames(dut):
    cfg = load_config()
    p = cfg["params"]
    w, h, bits = p.get("width", 352), p.get("height", 288), p.get("data_width", 8)
    tb = LineDelayTB(dut, cfg, out_width=w, out_height=h)
    frames = frames_from_config(cfg, w, h, bits)
    report = await run_scenario(tb, frames, token_after=cfg.get("token_after"),
                                token_frame=frames_from_config(dict(frames=["random:99"]), w, h, bits)[0])
    write_report(cfg, report)
