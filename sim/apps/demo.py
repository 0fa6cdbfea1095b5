"""``make demo``: a real image through the generated VHDL in GHDL, pictures to ``build/demo/``.

The image (Middlebury Tsukuba, left view, centre 352x288) is streamed into the VHDL that MyHDL wrote
for :func:`eyestereo.hdl.harris.sobel.sobel` and for :func:`eyestereo.hdl.harris.harris_mono.harris_mono`, simulated
by GHDL under cocotb; each bench checks the output bit for bit against the numpy model before the
pictures are written. The Harris run is made twice, as in thesis Fig. 5.3/5.4: one global threshold,
and 4x4 blocks with a threshold each, both aiming at the same number of corners.

The first step is the complete stereo front end (:mod:`eyestereo.sim.apps.cli_system`, small cameras) on a
stereo pair cut from the same image.

The output fits on one screen: one line per step (:class:`eyestereo.sim.apps.steps.StepRunner`: what ran,
on what, the result, where the pictures are); the simulators' own output goes to
``build/demo/logs/<step>.log``.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

import cv2
import numpy as np

from eyestereo.sim.lib.bench import make_frame
from eyestereo.sim.lib.runner import ROOT, run_bench
from eyestereo.sim.apps.steps import StepFailed, StepRunner
from eyestereo.tools.constants import FRAME_HEIGHT, FRAME_WIDTH, K_CODE_DEFAULT, NMS_DEFAULT, THRESHOLD_BLOCKS
from eyestereo.tools.models import harris_mono as hm
from eyestereo.tools.models import prethreshold as pt
from eyestereo.tools.models import sobel as model

IMAGE = "tsukuba_im3.png"
WIDTH, HEIGHT = FRAME_WIDTH, FRAME_HEIGHT


def gradient_picture(g: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """|G| of sfix[9,-3] codes (0..128) times 4, clipped to 0..255, border black."""
    out = np.clip(np.abs(g) * 4, 0, 255).astype(np.uint8)
    out[~mask] = 0
    return out


#: The complete front end's step: the fastest simulator here (Verilator on MyHDL's Verilog of the top if
#: installed, else GHDL), a size and frame count that keep make demo under 5 minutes on 2 cores (docs/system.md).
SYSTEM_SIZE = (96, 72)
SYSTEM_FRAMES = 2
SYSTEM_MODES = ["sequential", "overlapped"]

TARGET = 300  # corners per frame, both runs


def block_thresholds(frame: np.ndarray, blocks: tuple[int, int], target: int) -> list[int]:
    """Threshold codes that leave about ``target`` corners in the frame, spread evenly over the blocks."""
    s = hm.harris_stages(frame, K_CODE_DEFAULT, [0] * (blocks[0] * blocks[1]), blocks=blocks, nms=NMS_DEFAULT)
    cand = (s["flags"] > 0) & s["mask"]
    idx = pt.block_index(*frame.shape, blocks)
    per = max(1, target // (blocks[0] * blocks[1]))
    out = []
    for b in range(blocks[0] * blocks[1]):
        vals = np.sort(s["cornerness"][cand & (idx == b)])[::-1]
        out.append(int(vals[per]) if len(vals) > per else 0)
    return out


def draw_corners(frame: np.ndarray, flags: np.ndarray, blocks: tuple[int, int]) -> np.ndarray:
    img = cv2.cvtColor(frame.astype(np.uint8), cv2.COLOR_GRAY2BGR)
    h, w = frame.shape
    for i in range(1, blocks[0]):
        cv2.line(img, (i * w // blocks[0], 0), (i * w // blocks[0], h - 1), (255, 160, 0), 1)
    for i in range(1, blocks[1]):
        cv2.line(img, (0, i * h // blocks[1]), (w - 1, i * h // blocks[1]), (255, 160, 0), 1)
    for x, y in hm.features(flags):
        cv2.circle(img, (int(x), int(y)), 3, (0, 0, 255), 1, lineType=cv2.LINE_AA)
    return img


def run_harris(out: Path, frame: np.ndarray, blocks: tuple[int, int]) -> tuple[np.ndarray, dict]:
    thr = block_thresholds(frame, blocks, TARGET)
    name = f"harris_{blocks[0]}x{blocks[1]}"
    dump = out / f"{name}_frames.npy"
    report = run_bench("harris_mono", "tb_harris_mono",
                       dict(frames=[f"file:{IMAGE}"], duty=1.0, k=K_CODE_DEFAULT, thresholds=thr, dump=str(dump)),
                       name=f"demo_{name}", params=dict(width=WIDTH, height=HEIGHT, blocks=blocks, nms=NMS_DEFAULT))
    flags = np.load(dump)[0]
    _, mask = hm.harris_mono(frame, K_CODE_DEFAULT, thr, blocks=blocks, nms=NMS_DEFAULT)
    return flags * mask, report


def rig_view(scene: np.ndarray, side: str) -> np.ndarray:
    """What the synthetic rig's ``side`` camera sees of ``scene`` (a rectified view): the scene through the
    inverse of the rig's backward map (fixed-point iteration), so that the top, rectifying with the rig's
    calibration (``rig:WxH``), gives the scene back row-aligned."""
    from eyestereo.tools.rectify.synthetic_rig import rig_maps

    h, w = scene.shape
    m = rig_maps(w, h)
    mx, my = m[f"{side}_x"].astype(np.float32), m[f"{side}_y"].astype(np.float32)
    v, u = np.mgrid[0:h, 0:w].astype(np.float32)
    px, py = u.copy(), v.copy()
    for _ in range(20):  # p such that M(p) = (u, v)
        px -= cv2.remap(mx, px, py, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE) - u
        py -= cv2.remap(my, px, py, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE) - v
    return cv2.remap(scene, px, py, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)


def write_png(path: Path, img: np.ndarray) -> None:
    if not cv2.imwrite(str(path), img):
        raise OSError(f"cannot write {path}")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description="Run the Sobel and Harris VHDL on a real image in GHDL and write PNGs.")
    ap.add_argument("--out", type=Path, default=ROOT / "build" / "demo")
    args = ap.parse_args(argv)
    out: Path = args.out.resolve()
    out.mkdir(parents=True, exist_ok=True)
    steps = StepRunner(out / "logs", width=29)
    from eyestereo.sim.lib.runner import fastest_simulator

    system_sim = fastest_simulator()
    frame = make_frame(f"file:{IMAGE}", WIDTH, HEIGHT)
    write_png(out / "input.png", frame.astype(np.uint8))
    rel = os.path.relpath(out)
    steps.say(f"make demo: {IMAGE} (Middlebury Tsukuba, left view), centre {WIDTH}x{HEIGHT}, through the generated "
              f"VHDL in GHDL; pictures in {rel}/, simulator logs in {rel}/logs/")

    def sobel_step():
        dump = out / "sobel_frames.npy"
        report = run_bench("sobel", "tb_sobel", dict(frames=[f"file:{IMAGE}"], duty=1.0, dump=str(dump)),
                           name="demo", params=dict(width=WIDTH, height=HEIGHT))
        words = np.load(dump)[0]
        undefined = int((words < 0).sum())  # the bench stores a beat with U/X bits as -1
        ix, iy = model.unpack(np.where(words < 0, 0, words))
        _, _, mask = model.sobel(frame)
        write_png(out / "sobel_abs_ix.png", gradient_picture(ix, mask))
        write_png(out / "sobel_abs_iy.png", gradient_picture(iy, mask))
        und = f", {undefined} border words undefined (U/X)" if undefined else ""
        return (f"{report['pixels_compared']} interior pixels bit-exact with the model{und}, "
                f"{report['cycles']} clocks -> sobel_abs_ix.png, sobel_abs_iy.png")

    def harris_step(blocks):
        def step():
            flags, rep = run_harris(out, frame, blocks)
            name = f"harris_{blocks[0]}x{blocks[1]}.png"
            write_png(out / name, draw_corners(frame, flags, blocks))
            return f"{int(flags.sum())} corners, {rep['pixels_compared']} flags bit-exact with the model -> {name}"
        return step

    def system_step():
        # the complete front end on a stereo pair cut from the Tsukuba view (the right view 6 px further),
        # small cameras so that the step takes a minute or two: `eyestereo sim system` for other sizes
        import json

        from eyestereo.sim.apps.cli_system import main_system

        img = cv2.imread(str(ROOT / "tests" / "data" / IMAGE), cv2.IMREAD_GRAYSCALE)
        lp, rp = out / "system_left.png", out / "system_right.png"
        w, h = SYSTEM_SIZE
        scenes = [cv2.resize(img[100:196, x0:x0 + 128], (w, h), interpolation=cv2.INTER_AREA) for x0 in (150, 156)]
        write_png(lp, rig_view(scenes[0], "left"))
        write_png(rp, rig_view(scenes[1], "right"))
        summary = main_system(lp, rp, out / "system", size=SYSTEM_SIZE, frames=SYSTEM_FRAMES, modes=SYSTEM_MODES,
                              sim=system_sim)
        (out / "system.json").write_text(json.dumps(summary, indent=2) + "\n")
        mt = summary["matches_last_frame"]
        return (f"{w}x{h} cameras at 18/17.9 MHz, " + ", ".join(
            f"{summary['frames'][m]} frames {m} {summary['fps'][m]:.0f} fps" for m in SYSTEM_MODES) +
            f" (simulated), {mt['matches']} matches, bit-exact: {'yes' if summary['bit_exact'] else 'no'} "
            "-> system/rectified.png, system/matches.png")

    try:
        steps.run(f"stereo front end ({'Verilator' if system_sim == 'verilator' else 'GHDL'})", system_step)
        steps.run("sobel (VHDL, GHDL)", sobel_step)
        steps.run("harris_mono, 1 threshold", harris_step((1, 1)))
        steps.run("harris_mono, {}x{} thresholds".format(*THRESHOLD_BLOCKS), harris_step(THRESHOLD_BLOCKS))
    except StepFailed:
        return 1
    steps.say(f"4 steps, every output bit-exact, {steps.seconds:.0f} s; input.png and the pictures are in {rel}/")
    return steps.finish()


if __name__ == "__main__":
    sys.exit(main())
