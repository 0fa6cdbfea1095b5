"""Python side of :func:`eyestereo.hdl.memory.sram_arbiter.sram_arbiter`: the address map, the words it stores, and
the scoreboard models the benches check it with (pure Python/numpy).

* :class:`AddressMap` -- where every frame buffer lives in the 1M words (documented in docs/sram.md).
* :data:`CAMERA_WORD`, :data:`RECT_WORD` -- the packed words of the camera and rectified buffers.
* :func:`fetch_addresses` -- the reads a pixel-fetch request turns into.
* :class:`DoubleBufferModel` -- the buffer states of :func:`eyestereo.hdl.memory.frame_buffers.double_buffer`.
* :class:`Scoreboard` -- every word's expected value, in the order the SRAM sees the accesses.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from eyestereo.tools.constants import FRAME_HEIGHT, FRAME_WIDTH
from eyestereo.tools.packed import PackedWord
from eyestereo.tools.sram import DATA_BITS, WORDS, power_up_word

__all__ = ["AddressMap", "match_offset", "list_words", "CAMERA_WORD", "RECT_WORD", "Master", "MASTER_TABLE",
           "MASTERS", "WRITERS", "fetch_addresses", "DoubleBufferModel", "Scoreboard", "STAT"]

#: A camera word: the pixel's Y in bits 7..0, its chroma sample (U for even x, V for odd x) in 15..8.
CAMERA_WORD = PackedWord("camera", [("y", 8), ("c", 8)])
#: A rectified word: the left image's pixel (x, y) in bits 7..0, the right image's in 15..8.
RECT_WORD = PackedWord("rectified pair", [("left", 8), ("right", 8)])

@dataclass(frozen=True)
class Master:
    """One master of the arbiter, described once: the arbiter generates its engine, its place in the round
    robin and its status counters from this; the benches their agents and checks.

    ``name``: its port on the arbiter (and its name in the counters and reports); ``engine``: ``"camera"``
    (a camera's queue read port), ``"stereo"`` (the rectified stereo image stream), ``"features"`` (feature
    lists on a queue read port) -- the three *writers*, each into its own double buffer named like the
    master -- or ``"fetch"`` (the pixel fetch port's reads) or ``"host"`` (reads and writes);
    ``urgent``: a writer of a stream that cannot wait (served before the round robin); ``burst``: the
    arbiter parameter that sets its turn's length; ``read_tag``: the bits above the fetch index in the tag
    of its reads (who gets the read data back).
    """

    name: str
    engine: str
    urgent: bool = False
    burst: str = "burst"
    read_tag: int = 0

    @property
    def writer(self) -> bool:
        return self.engine in WRITER_ENGINES


WRITER_ENGINES = ("camera", "stereo", "features")

#: The arbiter's masters, in its order (the index of the counters and the round robin).
MASTER_TABLE = (
    Master("cam0", "camera", urgent=True),
    Master("cam1", "camera", urgent=True),
    Master("fetch", "fetch", burst="fetch_burst"),
    Master("rect", "stereo", urgent=True),
    Master("feat", "features"),
    Master("host", "host", burst="host_burst", read_tag=1),
)
MASTERS = tuple(m.name for m in MASTER_TABLE)
#: The writers (and their double buffers), in the arbiter's order (the order of the buffer status words).
WRITERS = tuple(m.name for m in MASTER_TABLE if m.writer)

#: Register map of the arbiter's status port (word address -> meaning); 32-bit words.
STAT = {
    **{i: f"words moved, {m}" for i, m in enumerate(MASTERS)},
    **{len(MASTERS) + i: f"clocks waited, {m}" for i, m in enumerate(MASTERS)},
    12: "clocks since reset",
    13: "camera 0 frames: dropped << 16 | published",
    14: "camera 1 frames: dropped << 16 | published",
    15: "rectified frames: dropped << 16 | published",
    16: "feature lists: dropped << 16 | published",
    17: "frames overwritten: camera 1 << 16 | camera 0",
    18: "frames overwritten: features << 16 | rectified",
    19: "rectified-writer words lost << 16 | buffer states (features 15..12, rectified 11..8, camera 1 7..4, "
        "camera 0 3..0; each buffer 1 << 2 | buffer 0, 0 FREE 1 WRITING 2 FULL 3 READING)",
    20: "feature list in buffer 0: overflowed << 31 | words",
    21: "feature list in buffer 1: overflowed << 31 | words",
}


@dataclass(frozen=True)
class AddressMap:
    """The frame buffers in the SRAM's words, packed from address 0 (one word per pixel, row by row).

    ======================  ============================  ===============================================
    region                  words                         content
    ======================  ============================  ===============================================
    camera c, buffer b      width x height each (4)       :data:`CAMERA_WORD` of pixel (x, y) at
                                                          base + y * width + x
    rectified, buffer b     width x height each (2)       :data:`RECT_WORD` (left and right pixel of (x, y))
    feature list, buffer b  ``feature_words`` each (2)    the list's words in order
    disparity, buffer b     width x height each (2)       ``dense=True`` only: the dense option's disparity
                                                          code of left pixel (x, y) (1/16 px, 0xFFFF none)
    host area               the rest up to 1M             free for the host's own use
    ======================  ============================  ===============================================

    ``cameras=False`` (the front end's ``rectify="stream"``: the cameras go to the line cache, not the memory): no
    camera buffers, the rectified buffers from address 0 and the rest moved down with them, so that 640x480
    frames fit the 1M words too (2 x 307,200 + the lists). The camera writers' bases are then 0 (they never write).

    ``dense=True`` (the front end's ``dense`` option): two disparity buffers after the feature lists, written through
    the host port by :func:`~eyestereo.hdl.system.disparity_writer.disparity_writer` (``bases("disp")``).
    """

    width: int = FRAME_WIDTH
    height: int = FRAME_HEIGHT
    feature_words: int = 8192
    words: int = WORDS
    cameras: bool = True
    dense: bool = False

    def __post_init__(self):
        for name in ("width", "height", "feature_words"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < 2:
                raise ValueError(f"AddressMap {name} must be an int >= 2, got {v!r}")
        if self.host_base > self.words:
            raise ValueError(f"{self.width}x{self.height} frames: {self._frames + 2 * self.dense} buffers of "
                             f"{self.frame} words and 2 feature lists of {self.feature_words} need {self.host_base} "
                             f"words, the SRAM has {self.words}")

    @property
    def _frames(self) -> int:
        """Frame buffers in the map: 4 camera and 2 rectified, or the 2 rectified alone."""
        return 6 if self.cameras else 2

    @property
    def frame(self) -> int:
        return self.width * self.height

    def camera(self, cam: int, buf: int) -> int:
        """Base address of camera ``cam``'s buffer ``buf``."""
        self._check(cam, buf)
        if not self.cameras:
            raise ValueError("this map has no camera buffers (cameras=False)")
        return (2 * cam + buf) * self.frame

    def rectified(self, buf: int) -> int:
        self._check(0, buf)
        return (self._frames - 2 + buf) * self.frame

    def features(self, buf: int) -> int:
        self._check(0, buf)
        return self._frames * self.frame + buf * self.feature_words

    def disparity(self, buf: int) -> int:
        """Base address of disparity buffer ``buf`` (``dense=True`` only)."""
        self._check(0, buf)
        if not self.dense:
            raise ValueError("this map has no disparity buffers (dense=False)")
        return self._frames * self.frame + 2 * self.feature_words + buf * self.frame

    def bases(self, writer: str) -> tuple[int, int]:
        """Base addresses of the two buffers of ``writer`` (a name of :data:`WRITERS`, or ``"disp"``: the
        disparity buffers of a ``dense`` map)."""
        if writer in ("cam0", "cam1"):
            if not self.cameras:
                return 0, 0
            return self.camera(int(writer[-1]), 0), self.camera(int(writer[-1]), 1)
        if writer == "rect":
            return self.rectified(0), self.rectified(1)
        if writer == "feat":
            return self.features(0), self.features(1)
        if writer == "disp":
            return self.disparity(0), self.disparity(1)
        raise ValueError(f"no buffers for {writer!r}: the writers are {WRITERS} (and 'disp')")

    def size(self, writer: str) -> int:
        """Words of each buffer of ``writer``."""
        self.bases(writer)
        return self.feature_words if writer == "feat" else self.frame

    @property
    def host_base(self) -> int:
        return (self._frames + 2 * self.dense) * self.frame + 2 * self.feature_words

    def pixel(self, base: int, x, y):
        """Address of pixel (x, y) in the frame buffer at ``base`` (numpy arrays welcome)."""
        return base + np.asarray(y) * self.width + np.asarray(x)

    def regions(self) -> list[tuple[str, int, int]]:
        """(name, first address, words) of every region, in address order."""
        out = [(f"camera {c} buffer {b}", self.camera(c, b), self.frame) for c in (0, 1) for b in (0, 1)
               if self.cameras]
        out += [(f"rectified buffer {b}", self.rectified(b), self.frame) for b in (0, 1)]
        out += [(f"feature list {b}", self.features(b), self.feature_words) for b in (0, 1)]
        out += [(f"disparity buffer {b}", self.disparity(b), self.frame) for b in (0, 1) if self.dense]
        out.append(("host area", self.host_base, self.words - self.host_base))
        return out

    def table(self) -> str:
        lines = ["| region | first word | last word | words |", "|---|---:|---:|---:|"]
        for name, a, n in self.regions():
            lines.append(f"| {name} | {a:#07x} | {a + n - 1:#07x} | {n:,} |")
        return "\n".join(lines)

    @staticmethod
    def _check(cam, buf):
        if cam not in (0, 1) or buf not in (0, 1):
            raise ValueError(f"camera and buffer must be 0 or 1, got {cam}, {buf}")


#: (dx, dy) of fetch index i: 0 = (x+1, y+1), 1 = (x, y+1), 2 = (x+1, y), 3 = (x, y).
FETCH_OFFSETS = ((1, 1), (0, 1), (1, 0), (0, 0))


def match_offset(max_features: int) -> int:
    """The word of a feature-list buffer where the front end's matcher option writes the frame's match list: after
    the longest feature list (2 words per feature) and its trailer (2 words); the words between are filler."""
    return 2 * max_features + 2


def list_words(max_features: int, max_matches: int | None = None) -> int:
    """The words a feature-list buffer needs: the longest feature list and its trailer, and with the matcher option
    (``max_matches`` given) the longest match list (3 words per match) and its trailer (3) after
    :func:`match_offset`."""
    return match_offset(max_features) + (0 if max_matches is None else 3 * max_matches + 3)


def fetch_addresses(amap: AddressMap, base: int, x: int, y: int, mask: int) -> list[tuple[int, int]]:
    """[(index, address)] of the reads a fetch request makes, in the order they are answered."""
    if not 1 <= mask <= 15:
        raise ValueError(f"a fetch mask is 1..15, got {mask}")
    out = []
    for i, (dx, dy) in enumerate(FETCH_OFFSETS):
        if (mask >> i) & 1:
            if x + dx >= amap.width or y + dy >= amap.height:
                raise ValueError(f"fetch index {i} of ({x}, {y}) is outside the {amap.width}x{amap.height} frame")
            out.append((i, int(amap.pixel(base, x + dx, y + dy))))
    return out


# ------------------------------------------------------------------------------------------------------
FREE, WRITING, FULL, READING = range(4)


@dataclass
class DoubleBufferModel:
    """Clock-true model of :func:`eyestereo.hdl.memory.frame_buffers.double_buffer`: call :meth:`clock` once per
    rising edge with the inputs of the clock that edge ends; the attributes are then the registers.

    The rules: a consumer's take (``c_take`` while a FULL buffer exists and none is held) takes the
    newest FULL buffer and wins over a producer's request in the same clock; a producer's request
    (``p_start``, held until answered) gets a FREE buffer if there is one, else the older FULL one (the
    newest frame stays for the consumer), never one being written or read; it is answered a clock later
    (``p_grant`` with ``p_gbuf``, or ``p_deny``: the frame is dropped).
    """

    state: list = field(default_factory=lambda: [FREE, FREE])
    newest: int = 0
    held: bool = False
    buf: int = 0
    p_grant: bool = False
    p_gbuf: int = 0
    p_deny: bool = False
    published: int = 0
    dropped: int = 0
    overwritten: int = 0

    def c_avail(self) -> bool:
        return FULL in self.state and not self.held

    def take_choice(self) -> int:
        full = [b for b in (0, 1) if self.state[b] == FULL]
        return self.newest if len(full) == 2 else (full[0] if full else 0)

    def pick(self, taking: int | None) -> int | None:
        ok = [b for b in (0, 1) if self.state[b] in (FREE, FULL) and b != taking]
        if len(ok) == 2:
            if self.state[0] == self.state[1]:
                return 1 - self.newest
            return 0 if self.state[0] == FREE else 1
        return ok[0] if ok else None

    def clock(self, *, p_start=False, p_done=False, p_done_buf=0, p_abort=False, p_abort_buf=0, c_take=False,
              c_release=False) -> None:
        taking = c_take and self.c_avail()
        tb = self.take_choice() if taking else None
        asking = p_start and not self.p_grant and not self.p_deny
        pick = self.pick(tb)
        new = list(self.state)
        starting = asking and pick is not None
        self.p_grant, self.p_deny = starting, asking and pick is None
        if pick is not None:
            self.p_gbuf = pick
        elif asking:
            pass
        if starting:
            if self.state[pick] == FULL:
                self.overwritten += 1
            new[pick] = WRITING
        if asking and pick is None:
            self.dropped += 1
        if p_done:
            self.published += 1
            self.newest = p_done_buf
            new[p_done_buf] = FULL
        if p_abort:
            new[p_abort_buf] = FREE
        if c_release and self.held:
            self.held = False
            new[self.buf] = FREE
        elif taking:
            self.held = True
            self.buf = tb
            new[tb] = READING
        self.state = new


# ------------------------------------------------------------------------------------------------------
class Scoreboard:
    """Expected SRAM contents, updated in the order the accesses reach the SRAM.

    ``write(addr, data, be)`` as a write is issued; ``read(addr)`` returns what a read issued now must
    return (the last word written, or the part's power-up pattern). Counts reads and writes checked.
    """

    def __init__(self, bits: int = DATA_BITS):
        self.bits = bits
        self.mem: dict[int, int] = {}
        self.reads = 0
        self.writes = 0

    def write(self, addr: int, data: int, be: int = 3) -> None:
        old = self.mem.get(addr, power_up_word(addr, self.bits))
        for b in range(self.bits // 8):
            if (be >> b) & 1:
                m = 0xFF << (8 * b)
                old = (old & ~m) | (data & m)
        self.mem[addr] = old
        self.writes += 1

    def read(self, addr: int) -> int:
        self.reads += 1
        return self.mem.get(addr, power_up_word(addr, self.bits))

    def peek(self, addr: int) -> int:
        return self.mem.get(addr, power_up_word(addr, self.bits))

    def frame(self, base: int, width: int, height: int) -> np.ndarray:
        """The expected words of a width x height buffer at ``base``."""
        return np.array([[self.peek(base + y * width + x) for x in range(width)] for y in range(height)],
                        dtype=np.int64)


# ------------------------------------------------------------------------------------------------------
@dataclass
class Run:
    """One frame (or list) as written into a buffer: consecutive words from the buffer's base."""

    buf: int
    start: int   # SRAM edge of its first write
    end: int     # SRAM edge of its last write so far
    words: list
    item: int | None = None   # index of the sent frame/list it matches
    complete: bool = False


class BufferHistory:
    """What a double buffer held over time, rebuilt from the SRAM's write log (checks the writer).

    ``writes``: (edge, addr, word) of every write in SRAM order (writes outside the two buffers are
    ignored). ``sent``: the frames (flattened word lists) the producer was given, in order;
    ``stored(item)`` maps a sent item to the words its buffer must hold (e.g. a truncated list).
    Every run of writes must start at a buffer's base and continue word by word; runs must match sent
    items in order (skipped items were dropped). Raises AssertionError with the first fault.
    """

    def __init__(self, name: str, bases: tuple[int, int], size: int, writes, sent: list, *, stored=None):
        self.name = name
        self.bases = bases
        self.size = size
        stored = stored or (lambda w: list(w))
        self.expect = [stored(w) for w in sent]
        self.runs: list[Run] = []
        cur: dict[int, Run] = {}
        last_item = -1
        for edge, addr, word in writes:
            b = next((i for i, base in enumerate(bases) if base <= addr < base + size), None)
            if b is None:
                continue
            off = addr - bases[b]
            if off == 0:
                run = Run(b, edge, edge, [word])
                self.runs.append(run)
                cur[b] = run
            else:
                run = cur.get(b)
                assert run is not None and off == len(run.words), (
                    f"{name}: write of edge {edge} to buffer {b} word {off} does not continue a frame "
                    f"({'no frame started' if run is None else f'{len(run.words)} words written'})")
                run.words.append(word)
                run.end = edge
        # match runs to sent items, in order
        for run in self.runs:
            k = last_item + 1
            n = len(run.words)
            while k < len(self.expect) and self.expect[k][:n] != run.words:
                k += 1
            assert k < len(self.expect), (f"{name}: the frame written to buffer {run.buf} from edge {run.start} "
                                          f"({n} words) matches no frame sent after frame {last_item}")
            run.item = k
            run.complete = n == len(self.expect[k])
            last_item = k

    def complete_runs(self) -> list[Run]:
        return [r for r in self.runs if r.complete]

    def word_at(self, edge: int, addr: int) -> int:
        """The word a read of ``addr`` at SRAM edge ``edge`` must return; AssertionError if the frame in
        that buffer was not completely written then (a half-written frame) or was being overwritten."""
        b = next((i for i, base in enumerate(self.bases) if base <= addr < base + self.size), None)
        assert b is not None, f"{self.name}: address {addr:#07x} is in neither buffer"
        before = [r for r in self.runs if r.buf == b and r.start < edge]
        assert before, f"{self.name}: read of {addr:#07x} at edge {edge}: nothing was written to buffer {b} yet"
        run = before[-1]
        assert run.complete and run.end < edge, (
            f"{self.name}: read of {addr:#07x} at edge {edge} sees a half-written frame in buffer {b} "
            f"(frame {run.item}: {len(run.words)} words written from edge {run.start} to {run.end})")
        off = addr - self.bases[b]
        assert off < len(run.words), f"{self.name}: read of word {off} beyond the list of {len(run.words)} words"
        return run.words[off]
