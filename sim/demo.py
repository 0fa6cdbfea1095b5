"""``make demo``: a real image through the generated Sobel VHDL in GHDL, pictures to ``build/demo/``.

The image (Middlebury Tsukuba, left view, centre 352x288) is streamed into the VHDL that MyHDL wrote
for :func:`eyestereo.hdl.sobel.sobel`, simulated by GHDL under cocotb; the bench checks the output bit
for bit against the numpy model before the pictures are written.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import cv2
import numpy as np

from eyestereo.sim.bench import make_frame
from eyestereo.sim.runner import ROOT, run_bench
from eyestereo.tools import sobel as model

IMAGE = "tsukuba_im3.png"
WIDTH, HEIGHT = 352, 288


def gradient_picture(g: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """|G| of sfix[9,-3] codes (0..128) times 4, clipped to 0..255, border black."""
    out = np.clip(np.abs(g) * 4, 0, 255).astype(np.uint8)
    out[~mask] = 0
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description="Run the Sobel VHDL on a real image in GHDL and write PNGs.")
    ap.add_argument("--out", type=Path, default=ROOT / "build" / "demo")
    args = ap.parse_args(argv)
    out: Path = args.out.resolve()
    out.mkdir(parents=True, exist_ok=True)
    dump = out / "sobel_frames.npy"
    t0 = time.perf_counter()
    try:
        report = run_bench("sobel", "tb_sobel", dict(frames=[f"file:{IMAGE}"], duty=1.0, dump=str(dump)),
                           name="demo", params=dict(width=WIDTH, height=HEIGHT))
    except (AssertionError, RuntimeError) as e:
        print(f"make demo: the GHDL run failed: {e}", file=sys.stderr)
        return 1
    seconds = time.perf_counter() - t0
    words = np.load(dump)[0]
    ix, iy = model.unpack(words)
    frame = make_frame(f"file:{IMAGE}", WIDTH, HEIGHT)
    _, _, mask = model.sobel(frame)
    written = {
        "input.png": frame.astype(np.uint8),
        "sobel_abs_ix.png": gradient_picture(ix, mask),
        "sobel_abs_iy.png": gradient_picture(iy, mask),
    }
    for name, img in written.items():
        if not cv2.imwrite(str(out / name), img):
            print(f"make demo: cannot write {out / name}", file=sys.stderr)
            return 1
    print(f"Sobel VHDL in GHDL on {IMAGE} ({WIDTH}x{HEIGHT}): {report['pixels_compared']} interior pixels "
          f"bit-exact with the numpy model, {report['cycles']} clock cycles simulated in {seconds:.1f} s")
    for name in written:
        print(f"  {out / name}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
