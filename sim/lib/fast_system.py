"""The Python side of the fast whole-system harness (:mod:`eyestereo.sim.harnesses.frontend_harness`).

* :func:`write_script`: a camera bus schedule (:func:`eyestereo.tools.camera.frame_schedule`'s runs, and ``stop``
  runs: PCLK held for n periods) as the camera player's script file.
* :class:`Backdoor`: the SRAM part's backdoor read (a buffer's words straight from the part's array, no bus).
* :class:`LeanAxiLite`: the host driver's bus on the harness's AXI4-Lite port, awake only while a transfer is
  in flight (no task on every clock: the register traffic of the host's handshake costs a few clocks of Python
  each, the waits between polls none).
* :func:`sram_rules`: the part's rule counters as a report, and the check that none was broken.
* :class:`FastTB`: the harness's clocks, resets, camera scripts, host driver and backdoor, for its benches.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, ReadOnly, RisingEdge, Timer

from eyestereo.sim.lib.frontend_model import model_params
from eyestereo.sim.lib.harness_files import DUMP_FILE, RUN_KINDS, RUN_SHIFT, SCRIPT_FILES, SRAM_RULES
from eyestereo.tools.camera import CameraTiming, frame_schedule, run_length
from eyestereo.tools.host_driver import HostDriver
from eyestereo.tools.models.sram_arbiter import AddressMap, list_words

#: The longest run one header holds (longer ones are split).
MAX_RUN = (1 << RUN_SHIFT) - 1


def script_lines(runs) -> list[str]:
    """The script of a schedule: one decimal integer per line (module docstring of the harness)."""
    out: list[str] = []
    for kind, p in runs:
        if kind not in RUN_KINDS:
            raise ValueError(f"camera script: unknown run kind {kind!r} (one of {', '.join(RUN_KINDS)})")
        n = run_length((kind, p))
        if n <= 0:
            continue
        if kind == "line":
            if n > MAX_RUN:
                raise ValueError(f"camera script: a line of {n} bytes is longer than a run can be ({MAX_RUN})")
            b = np.asarray(p, np.int64)
            if b.min() < 0 or b.max() > 255:
                raise ValueError("camera script: line bytes must be 0..255")
            pad = np.zeros(-n % 3, np.int64)
            w = np.concatenate([b, pad]).reshape(-1, 3) @ np.array([1, 256, 65536], np.int64)
            out.append(str((RUN_KINDS[kind] << RUN_SHIFT) | n))
            out.extend(map(str, w.tolist()))
        else:
            while n > 0:
                m = min(n, MAX_RUN)
                out.append(str((RUN_KINDS[kind] << RUN_SHIFT) | m))
                n -= m
    return out


def write_script(path: Path, runs) -> int:
    """Write a camera script (whole, then renamed: never half a file); returns the samples it plays."""
    path = Path(path)
    tmp = path.with_name(path.name + f".{os.getpid()}.tmp")
    tmp.write_text("\n".join(script_lines(runs)) + "\n")
    tmp.replace(path)
    return sum(run_length(r) for r in runs)


class Backdoor:
    """The SRAM part's backdoor read on the harness ``dut`` (clocked by ``clk``; its ports ``<prefix>dump_*``)."""

    def __init__(self, dut, clk, prefix: str = "sram_"):
        self.dut, self.clk = dut, clk
        g = lambda n: getattr(dut, f"{prefix}{n}")  # noqa: E731
        self.addr, self.len, self.stb_port, self.ack = g("dump_addr"), g("dump_len"), g("dump_stb"), g("dump_ack")
        self.stb = 0
        self.words_read = 0

    async def read(self, addr: int, count: int) -> np.ndarray:
        """``count`` words from word ``addr`` (int64 array), straight from the part's array."""
        if not 0 < count <= 1 << 20 or not 0 <= addr < 1 << 20:
            raise ValueError(f"backdoor read of {count} words at {addr:#x}: outside the 1M-word part")
        self.addr.value = addr
        self.len.value = count
        self.stb ^= 1
        self.stb_port.value = self.stb
        while True:
            await RisingEdge(self.clk)
            await ReadOnly()
            if int(self.ack.value) == self.stb:
                break
        await RisingEdge(self.clk)  # out of the read-only phase: the caller may drive signals again
        words = np.loadtxt(DUMP_FILE, dtype=np.int64, ndmin=1)
        if words.size != count:
            raise AssertionError(f"backdoor read: {words.size} words in {DUMP_FILE}, {count} asked")
        self.words_read += count
        return words


class LeanAxiLite:
    """The host driver's bus (``read``, ``write``, ``wait``) on ``<prefix>_*`` of ``dut``: one transfer at a
    time, Python awake on the clocks of that transfer only; ``wait`` is a timer. A response other than OKAY
    is returned to the driver, which raises. ``timeout`` clocks without a handshake raise AssertionError."""

    def __init__(self, dut, prefix: str, clk, period_ns: float = 10.0, timeout: int = 1000, on_access=None):
        g = lambda n: getattr(dut, f"{prefix}_{n}")  # noqa: E731
        self.aw = (g("awvalid"), g("awready"), g("awaddr"), g("awprot"))
        self.w = (g("wvalid"), g("wready"), g("wdata"), g("wstrb"))
        self.b = (g("bvalid"), g("bready"), g("bresp"))
        self.ar = (g("arvalid"), g("arready"), g("araddr"), g("arprot"))
        self.r = (g("rvalid"), g("rready"), g("rdata"), g("rresp"))
        self.clk, self.period_ns, self.timeout = clk, period_ns, timeout
        for s in (self.aw[0], self.w[0], self.ar[0], self.b[1], self.r[1], self.aw[3], self.ar[3]):
            s.value = 0
        self.transfers = 0
        self.on_access = on_access  # called with (byte address, "read" or "write") for each transfer (coverage)

    async def _edge(self, what: str, n: int) -> None:
        if n > self.timeout:
            raise AssertionError(f"AXI4-Lite: no {what} within {self.timeout} clocks")
        await RisingEdge(self.clk)

    async def write(self, address: int, data: int, strb: int = 0xF) -> int:
        if self.on_access:
            self.on_access(int(address), "write")
        (awv, awr, awa, _), (wv, wr, wd, ws), (bv, br, bresp) = self.aw, self.w, self.b
        awa.value, wd.value, ws.value = int(address) & ~3, int(data) & 0xFFFFFFFF, int(strb)
        awv.value = wv.value = 1
        br.value = 1
        a_done = d_done = False
        n = 0
        while not (a_done and d_done):
            await self._edge("write address/data ready", n)
            n += 1
            a_done |= bool(awv.value) and bool(awr.value)
            d_done |= bool(wv.value) and bool(wr.value)
            if a_done:
                awv.value = 0
            if d_done:
                wv.value = 0
        while True:
            await ReadOnly()
            if int(bv.value):
                resp = int(bresp.value)
                break
            await self._edge("write response", n)
            n += 1
        await RisingEdge(self.clk)  # the response moves at this edge (bready high)
        br.value = 0
        self.transfers += 1
        return resp

    async def read(self, address: int) -> tuple[int, int]:
        if self.on_access:
            self.on_access(int(address), "read")
        (arv, arr, ara, _), (rv, rr, rd, rresp) = self.ar, self.r
        ara.value = int(address) & ~3
        arv.value = 1
        rr.value = 1
        n = 0
        while True:
            await self._edge("read address ready", n)
            n += 1
            if int(arr.value):
                break
        arv.value = 0
        while True:
            await ReadOnly()
            if int(rv.value):
                data, resp = int(rd.value), int(rresp.value)
                break
            await self._edge("read data", n)
            n += 1
        await RisingEdge(self.clk)  # the data moves at this edge (rready high)
        rr.value = 0
        self.transfers += 1
        return data, resp

    async def wait(self, clocks: int) -> None:
        await Timer(int(clocks) * self.period_ns, unit="ns")
        await RisingEdge(self.clk)


def sram_rules(dut, prefix: str = "sram_") -> dict:
    """The SRAM part's counters: accesses, rules broken (count, first rule and edge, every rule seen)."""
    g = lambda n: int(getattr(dut, f"{prefix}{n}").value)  # noqa: E731
    count = g("viol_count")
    rules = g("viol_rules")
    return dict(reads=g("reads"), writes=g("writes"), violations=count,
                first=None if not count else dict(rule=SRAM_RULES[g("viol_rule")], edge=g("viol_edge")),
                rules=[r for i, r in enumerate(SRAM_RULES) if rules >> i & 1])


class FastTB:
    """The harness's clocks, resets, camera scripts, host and backdoor."""

    def __init__(self, dut, cfg: dict):
        from eyestereo.hdl.rectify.calibration import calibration_param

        self.dut, self.cfg = dut, cfg
        self.cal = calibration_param(cfg["params"]["quantizers"], None, None)
        self.w, self.h = self.cal.width, self.cal.height
        self.mp = model_params(cfg["params"])
        self.timing = CameraTiming(width=self.w, height=self.h,
                                   **cfg.get("timing", dict(h_blank=64, v_sync=1, v_back=1, v_front=1)))
        self.amap = AddressMap(self.w, self.h,
                               cfg["params"].get("feature_words") or list_words(self.mp["max_features"]))
        self.bus = LeanAxiLite(dut, "bus", dut.clk)
        self.drv = HostDriver(self.bus)
        self.backdoor = Backdoor(dut, dut.clk)
        self.mhz = (cfg.get("cam_l_mhz", 18.0), cfg.get("cam_r_mhz", 17.9))

    async def start(self, frames=None, runs=None) -> None:
        """Clocks, resets, and each camera's script: ``frames`` played back to back, or ``runs`` (left, right:
        script runs, e.g. :func:`eyestereo.sim.lib.soak.camera_runs`). The cameras start at ``cam_go``."""
        d = self.dut
        Clock(d.clk, 10, unit="ns").start()
        Clock(d.hclk, int(round(1e3 / self.cfg.get("harris_mhz", 50.0) * 1000)), unit="ps").start()
        for base, mhz in zip((d.base_l, d.base_r), self.mhz):
            Clock(base, 2 * int(round(1e6 / mhz / 2)), unit="ps").start(start_high=False)
        for r in ("rst", "hrst", "wrst_l", "wrst_r"):
            getattr(d, r).value = 1
        d.cam_go.value = 0
        d.sram_dump_stb.value = 0
        if runs is None:
            runs = [frame_schedule([f[idx] for f in frames], self.timing) for idx in (0, 1)]
        for side, r in zip("lr", runs):
            write_script(SCRIPT_FILES[side], r)
        await ClockCycles(d.clk, 8)
        for r in ("rst", "hrst", "wrst_l", "wrst_r"):
            getattr(d, r).value = 0

    def camera_ns(self) -> float:
        return self.timing.frame_pclk * 1e3 / min(self.mhz)
