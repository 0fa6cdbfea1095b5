"""Traffic agents for the SRAM subsystem's ports, stepped once per clock by one bench loop.

Each agent has ``sample(clock)`` (called right after the rising edge that ends ``clock``: the handshakes
of that clock are complete, outputs are the values the DUT showed during it) and ``drive(clock)`` (sets
its inputs for ``clock``). One loop steps every agent, so Python wakes once per clock for the whole
bench; agents write a DUT input only when its value changes.
"""

from __future__ import annotations

import random
from collections import deque

from eyestereo.sim.lib.sram_model import read_int
from eyestereo.tools.models.sram_arbiter import FETCH_OFFSETS


class Pin:
    """A DUT input that is written only when its value changes."""

    def __init__(self, handle, value: int = 0):
        self.h = handle
        self.v = None
        self.set(value)

    def set(self, value: int) -> None:
        value = int(value)
        if value != self.v:
            self.h.value = value
            self.v = value


def port(dut, prefix, *names):
    return [getattr(dut, f"{prefix}_{n}") for n in names]


def offer(valid: Pin, pins, values) -> None:
    """Drive a beat or request: each of ``pins`` to its value, then ``valid`` high."""
    for pin, v in zip(pins, values, strict=True):
        pin.set(v)
    valid.set(1)


# ------------------------------------------------------------------------------------------------------
class CameraSource:
    """The read side of a camera's async FIFO: words arrive at the camera's rate, wait in a FIFO of
    ``depth`` words, and are offered on the queue read port.

    ``rate``: words per clock during a line (9 M words/s at 100 MHz = 0.09); ``hblank``/``vblank``: clocks
    without words after each line / frame. Frames are random 16-bit words. An arrival into a full FIFO
    is an overflow (recorded with its clock; the bench fails on it).
    """

    def __init__(self, dut, prefix, rng: random.Random, *, width, height, rate, depth, hblank=0, vblank=0):
        self.valid, self.data, self.eol, self.eof = (Pin(h) for h in port(dut, prefix, "valid", "data", "eol", "eof"))
        self.ready = getattr(dut, f"{prefix}_ready")
        self.rng = rng
        self.w, self.h = width, height
        self.rate, self.depth = rate, depth
        self.hblank, self.vblank = hblank, vblank
        self.fifo: deque = deque()
        self.frames: list[list[int]] = []   # every frame sent, flattened
        self.pos = 0                        # next pixel of the current frame
        self.acc = 0.0
        self.blank = 0
        self.max_fill = 0
        self.overflows: list[int] = []
        self.moved = 0
        self.enabled = True
        self.stopping = False
        self.offered = False
        self.limit = None  # frames to send (None: endless)

    def stop(self) -> None:
        """Finish the frame in progress, then send nothing more."""
        self.stopping = True

    @property
    def idle(self) -> bool:
        done = self.stopping or (self.limit is not None and len(self.frames) >= self.limit)
        return not self.fifo and self.valid.v == 0 and (not self.enabled or (done and self.pos in (0, self.w * self.h)))

    def _new_frame(self):
        self.frames.append([self.rng.randrange(1 << 16) for _ in range(self.w * self.h)])
        self.pos = 0

    def arrive(self, clock: int) -> None:
        if not self.enabled:
            return
        if self.blank:
            self.blank -= 1
            return
        self.acc += self.rate
        while self.acc >= 1.0:
            self.acc -= 1.0
            if not self.frames or self.pos == self.w * self.h:
                if self.stopping or (self.limit is not None and len(self.frames) >= self.limit):
                    self.acc = 0.0
                    return
                self._new_frame()
            x = self.pos % self.w
            eol = x == self.w - 1
            eof = eol and self.pos == self.w * self.h - 1
            if len(self.fifo) >= self.depth:
                self.overflows.append(clock)
            else:
                self.fifo.append((self.frames[-1][self.pos], eol, eof))
            self.pos += 1
            self.max_fill = max(self.max_fill, len(self.fifo))
            if eof and self.vblank:
                self.blank, self.acc = self.vblank, 0.0
                break
            if eol and self.hblank:
                self.blank, self.acc = self.hblank, 0.0
                break

    def sample(self, clock: int) -> None:
        if self.offered and read_int(self.ready):
            self.fifo.popleft()
            self.moved += 1

    def drive(self, clock: int) -> None:
        self.arrive(clock)
        if self.fifo:
            offer(self.valid, (self.data, self.eol, self.eof), self.fifo[0])
            self.offered = True
        else:
            self.valid.set(0)
            self.offered = False


# ------------------------------------------------------------------------------------------------------
class StereoSource:
    """The rectified stereo stream (8-bit pixels, cam): left and right pixel of each (x, y), one beat per
    clock with probability ``duty``; random frames, optionally a reset token after ``token_after`` pixels of
    the first frame. No back-pressure."""

    def __init__(self, dut, prefix, rng: random.Random, *, width, height, duty, frames=None, token_after=None):
        self.valid, self.data, self.eol, self.eof, self.cam = (
            Pin(h) for h in port(dut, prefix, "valid", "data", "eol", "eof", "cam"))
        self.rng = rng
        self.w, self.h = width, height
        self.duty = duty
        self.limit = frames  # frames to send (None: endless)
        self.sent: list[list[int]] = []    # frames sent, as packed words (left | right << 8), incl. aborted
        self.beats: deque = deque()
        self.token_after = token_after
        self.enabled = True
        self.tokens = 0

    def _queue_frame(self):
        n = self.w * self.h
        left = [self.rng.randrange(256) for _ in range(n)]
        right = [self.rng.randrange(256) for _ in range(n)]
        cut = self.token_after if (self.token_after is not None and not self.sent) else None
        self.sent.append([lv | (rv << 8) for lv, rv in zip(left, right)])
        for i in range(n if cut is None else cut):
            eol = i % self.w == self.w - 1
            eof = eol and i == n - 1
            self.beats.append((left[i], 0, eol, eof))
            self.beats.append((right[i], 1, eol, eof))
        if cut is not None:
            self.beats.append((0, 0, 0, 1))  # reset token
            self.tokens += 1

    def drive(self, clock: int) -> None:
        if not self.beats and self.enabled and (self.limit is None or len(self.sent) < self.limit):
            self._queue_frame()
        if self.beats and self.rng.random() < self.duty:
            offer(self.valid, (self.data, self.cam, self.eol, self.eof), self.beats.popleft())
        else:
            self.valid.set(0)

    def sample(self, clock: int) -> None:
        pass

    @property
    def idle(self) -> bool:
        return not self.beats and self.valid.v == 0


# ------------------------------------------------------------------------------------------------------
class FeatureSource:
    """Feature lists on a queue read port: random lengths 1..max_len (some longer than the buffer's
    capacity when asked), random words, one word offered per clock with probability ``duty``."""

    def __init__(self, dut, prefix, rng: random.Random, *, duty, max_len, lists=None):
        self.valid, self.data, self.eol, self.eof = (Pin(h) for h in port(dut, prefix, "valid", "data", "eol", "eof"))
        self.ready = getattr(dut, f"{prefix}_ready")
        self.rng = rng
        self.duty, self.max_len = duty, max_len
        self.limit = lists
        self.sent: list[list[int]] = []
        self.words: deque = deque()
        self.offered = False
        self.enabled = True
        self.moved = 0

    def drive(self, clock: int) -> None:
        if not self.words and self.enabled and (self.limit is None or len(self.sent) < self.limit):
            n = self.rng.randint(1, self.max_len)
            lst = [self.rng.randrange(1 << 16) for _ in range(n)]
            self.sent.append(lst)
            self.words.extend((w, i == n - 1) for i, w in enumerate(lst))
        if self.offered:
            return  # hold the offered word until it moves
        if self.words and self.rng.random() < self.duty:
            w, last = self.words[0]
            offer(self.valid, (self.data, self.eof, self.eol), (w, last, 0))
            self.offered = True
        else:
            self.valid.set(0)

    def sample(self, clock: int) -> None:
        if self.offered and read_int(self.ready):
            self.words.popleft()
            self.moved += 1
            self.offered = False
            self.valid.set(0)

    @property
    def idle(self) -> bool:
        return not self.words and not self.offered


# ------------------------------------------------------------------------------------------------------
class FetchMaster:
    """The rectifier's side of the pixel fetch port: requests for the held camera pair, every response
    recorded (checked offline against the frames written, see the bench).

    ``mode`` "frame": one pass over every (x, y) with x < width-1, y < height-1, left then right request,
    then release the pair; "continuous": random requests while the pair is held, released when a newer
    pair is waiting after at least ``min_requests``. ``duty``: probability of offering a request in a clock.
    ``full_mask``: share of requests asking all four pixels (others: a random non-empty mask).
    """

    def __init__(self, dut, prefix, rng: random.Random, *, width, height, duty=1.0, mode="frame",
                 full_mask=0.8, min_requests=64):
        self.valid, self.x, self.y, self.cam, self.mask = (
            Pin(h) for h in port(dut, prefix, "req_valid", "req_x", "req_y", "req_cam", "req_mask"))
        self.ready, self.rsp_valid, self.rsp_idx, self.rsp_data = port(
            dut, prefix, "req_ready", "rsp_valid", "rsp_idx", "rsp_data")
        self.rng = rng
        self.w, self.h = width, height
        self.duty, self.mode, self.full_mask, self.min_requests = duty, mode, full_mask, min_requests
        self.requests: list[tuple] = []     # (clock taken, x, y, cam, mask, (buf0, buf1))
        self.responses: list[tuple] = []    # (clock, idx, data)
        self.pending: deque = deque()       # (request number, idx) still to come
        self.plan: deque = deque()
        self.offer = None
        self.held = False
        self.bufs = (0, 0)
        self.done_pass = False
        self.release = False
        self.first_rsp: dict[int, int] = {}
        self.count = 0

    def start_pass(self, bufs) -> None:
        self.bufs = bufs
        self.done_pass = False
        self.count = 0
        if self.mode == "frame":
            self.plan = deque((x, y, c) for y in range(self.h - 1) for x in range(self.w - 1) for c in (0, 1))

    def _mask(self) -> int:
        return 15 if self.rng.random() < self.full_mask else self.rng.randint(1, 15)

    def _next(self):
        if self.mode == "frame":
            if not self.plan:
                return None
            x, y, c = self.plan.popleft()
        else:
            x, y, c = self.rng.randrange(self.w - 1), self.rng.randrange(self.h - 1), self.rng.randrange(2)
        return (x, y, c, self._mask())

    def sample(self, clock: int) -> None:
        if read_int(self.rsp_valid):
            assert self.pending, f"clock {clock}: a fetch response nobody asked for"
            n, want_idx = self.pending.popleft()
            idx, data = read_int(self.rsp_idx), read_int(self.rsp_data)
            assert data is not None, f"clock {clock}: fetch response data undefined"
            assert idx == want_idx, f"clock {clock}: fetch request {n}: response index {idx}, expected {want_idx}"
            self.responses.append((clock, idx, data))
            self.first_rsp.setdefault(n, clock)
        if self.offer is not None and read_int(self.ready):
            x, y, c, m = self.offer
            n = len(self.requests)
            self.requests.append((clock, x, y, c, m, self.bufs))
            self.pending.extend((n, i) for i in range(4) if (m >> i) & 1)
            self.offer = None
            self.count += 1
            self.valid.set(0)

    def drive(self, clock: int) -> None:
        if self.offer is not None:
            return
        if not self.held or self.done_pass:
            self.valid.set(0)
            return
        if self.rng.random() >= self.duty:
            self.valid.set(0)
            return
        r = self._next()
        if r is None:
            self.done_pass = True
            self.valid.set(0)
            return
        self.offer = r
        offer(self.valid, (self.x, self.y, self.cam, self.mask), r)

    @property
    def idle(self) -> bool:
        return self.offer is None and not self.pending


# ------------------------------------------------------------------------------------------------------
class HostMaster:
    """The host: random reads and writes in the host area (checked online against its own writes, in
    request order), and, as the consumer of the rectified images and feature lists, whole-buffer reads
    (checked offline). ``duty``: probability of a random access in a clock when idle."""

    def __init__(self, dut, prefix, rng: random.Random, *, area: tuple[int, int], duty=0.2, write_share=0.5,
                 pool=32):
        self.valid, self.we, self.addr, self.wdata, self.be = (
            Pin(h) for h in port(dut, prefix, "req_valid", "req_we", "req_addr", "req_wdata", "req_be"))
        self.ready, self.rsp_valid, self.rsp_data = port(dut, prefix, "req_ready", "rsp_valid", "rsp_data")
        self.rng = rng
        lo, hi = area
        self.pool = [rng.randrange(lo, hi) for _ in range(pool)]
        self.duty, self.write_share = duty, write_share
        self.mem: dict[int, int] = {}
        self.expect: deque = deque()      # per read: ("area", addr, value) or ("buffer", addr, None)
        self.buffer_reads: list[tuple[int, int]] = []  # (addr, data) of whole-buffer reads, in order
        self.jobs: deque = deque()        # whole-buffer reads queued: addresses
        self.offer = None
        self.accesses = 0
        self.area_reads = 0
        self.job_rate = 1.0  # probability of issuing the next whole-buffer read in a clock
        self.latency: list[int] = []  # clocks from a read taken to its data

    def read_buffer(self, addrs) -> None:
        self.jobs.extend(addrs)

    def sample(self, clock: int) -> None:
        if read_int(self.rsp_valid):
            assert self.expect, f"clock {clock}: a host response nobody asked for"
            kind, addr, want, t0 = self.expect.popleft()
            self.latency.append(clock - t0)
            data = read_int(self.rsp_data)
            assert data is not None, f"clock {clock}: host read data undefined"
            if kind == "area":
                assert data == want, (f"clock {clock}: host read of {addr:#07x} returned {data:#06x}, the last "
                                      f"word written there is {want:#06x}")
                self.area_reads += 1
            else:
                self.buffer_reads.append((addr, data))
        if self.offer is not None and read_int(self.ready):
            we, addr, data, be, kind = self.offer
            self.accesses += 1
            if we:
                old = self.mem.get(addr)
                if old is None:
                    from eyestereo.tools.sram import power_up_word
                    old = power_up_word(addr)
                for b in range(2):
                    if (be >> b) & 1:
                        old = (old & ~(0xFF << 8 * b)) | (data & (0xFF << 8 * b))
                self.mem[addr] = old
            elif kind == "area":
                from eyestereo.tools.sram import power_up_word
                self.expect.append(("area", addr, self.mem.get(addr, power_up_word(addr)), clock))
            else:
                self.expect.append(("buffer", addr, None, clock))
            self.offer = None
            self.valid.set(0)

    def drive(self, clock: int) -> None:
        if self.offer is not None:
            return
        if self.jobs and self.rng.random() < self.job_rate:
            self.offer = (0, self.jobs.popleft(), 0, 3, "buffer")
        elif self.rng.random() < self.duty:
            we = self.rng.random() < self.write_share
            be = self.rng.choice([3, 3, 1, 2]) if we else 3
            self.offer = (int(we), self.rng.choice(self.pool), self.rng.randrange(1 << 16), be, "area")
        else:
            self.valid.set(0)
            return
        offer(self.valid, (self.we, self.addr, self.wdata, self.be), self.offer[:4])

    @property
    def idle(self) -> bool:
        return self.offer is None and not self.jobs and not self.expect


__all__ = ["Pin", "offer", "CameraSource", "StereoSource", "FeatureSource", "FetchMaster", "HostMaster",
           "FETCH_OFFSETS"]
