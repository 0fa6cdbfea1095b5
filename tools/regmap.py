"""The register map of the stereo front end: one table, everything else made from it.

:data:`REGMAP` is the one description of the registers the processor sees on the register bus (AXI4-Lite,
:mod:`eyestereo.hdl.interfaces.axil`). From it come

* the VHDL side: :func:`eyestereo.hdl.system.register_bank.register_bank` elaborates its ports, decoder, registers
  and read multiplexer from this table (and :class:`eyestereo.hdl.system.register_bank.RegisterPorts` its port
  bundle);
* the host driver: :class:`eyestereo.tools.host_driver.HostDriver` (registers and fields by name, built
  from this table at import time);
* the bit-true model the benches check the VHDL against: :class:`eyestereo.tools.models.register_bank.RegisterBank`;
* the documentation: ``python -m eyestereo.tools.regmap`` (``make regs``) writes ``docs/registers.md`` and
  the register table in README.md (between ``<!-- regs:begin -->`` and ``<!-- regs:end -->``).

To change the map, edit :data:`REGISTERS` below and run ``make regs``; the bank, the driver and the
model follow by themselves (``tests/core/test_regmap.py`` checks the committed documents are current).

Register kinds (:data:`KINDS`): every register is one 32-bit word (``const``, ``rw``, ``pulse``,
``status``) or an aligned group of ``count`` words (``array``, ``window``, ``memory``); byte addresses,
word aligned (the low two address bits are ignored).

Values are checked here, once, for every user of the table: :meth:`Field.check` (a field's value),
:meth:`Register.check_value` (a word and its index), :meth:`Register.check_words` (a run of words) and
:func:`check_frame_size` (the bank's ``width``/``height``). A value that does not fit is refused with one
line naming the register, the value and the range, never masked into another value.

This module is plain Python (no MyHDL, no cocotb), so a host program can use it.
"""

from __future__ import annotations

import argparse
import numbers
import sys
from dataclasses import dataclass, field
from pathlib import Path

from eyestereo.tools.constants import DENSE_DEFAULTS, FRAME_MAX, FRAME_MIN, K_CODE_DEFAULT
from eyestereo.tools.packed import lookup

__all__ = ["Field", "Register", "RegisterMap", "REGISTERS", "REGMAP", "KINDS", "OKAY", "SLVERR", "K_BITS",
           "THRESHOLD_BITS", "ARB_WORDS", "RegisterMapError", "RegisterIndexError", "FRAME_MIN", "FRAME_MAX",
           "FRAME_CONTROL", "check_frame_size", "check_bits"]

#: AXI response codes the bank gives (AXI4-Lite has no EXOKAY; DECERR is not used).
OKAY, SLVERR = 0, 2

#: Port widths of the Harris side (tests/core/test_regmap.py checks them against the models:
#: ``tools.models.cornerness.K`` (ufix[8,8]) and ``tools.models.cornerness.OUT`` (the 20-bit threshold code)).
K_BITS = 8
THRESHOLD_BITS = 20
#: The k registers' reset: k = 0.04 as the k port's code (:data:`eyestereo.tools.constants.K_CODE_DEFAULT`).
K_RESET = K_CODE_DEFAULT

# The frame sizes the register bank is built for (its ``width``/``height`` parameters, which GEOMETRY
# reports) are eyestereo.tools.constants' FRAME_MIN..FRAME_MAX, re-exported here for the bank's users.

#: The ``connect`` of the fields wired to the SRAM arbiter's FrameControl, followed by the field's name (the
#: FrameControl member of that name): :func:`eyestereo.hdl.system.frame_handshake.frame_handshake` wires
#: every field whose ``connect`` says so.
FRAME_CONTROL = "sram_subsystem ctl_"

#: The SRAM arbiter's status words in its status port's order (names for the host driver; their meaning
#: is ``STAT`` in eyestereo.tools.models.sram_arbiter, which the test checks this against).
_MASTERS = ("cam0", "cam1", "fetch", "rect", "feat", "host")
ARB_WORDS = (tuple(f"moved_{m}" for m in _MASTERS) + tuple(f"waited_{m}" for m in _MASTERS)
             + ("clocks", "frames_cam0", "frames_cam1", "frames_rect", "frames_feat", "overwritten_cam",
                "overwritten_rect_feat", "buffer_states", "list0", "list1"))

KINDS = {
    "const": "read-only constant (an identification or an elaboration parameter)",
    "rw": "read/write, kept in the bank; each field drives an output port",
    "pulse": "write-only command: each 1 written makes its field's output port high for one clock; reads 0",
    "status": "read-only; each field is an input port of the bank, read as it is when the read is served",
    "array": "`count` read/write words kept in the bank (LUT-RAM copy for reading back, 0 after reset until "
             "written) and written through to a write port `<name>_we`, `<name>_addr`, `<name>_data`",
    "window": "`count` read-only words read through an external read port (address out, data in `latency` "
              "clocks later: :class:`eyestereo.hdl.interfaces.sram_bus.StatPort`)",
    "memory": "`count` 16-bit SRAM words through the arbiter's host port "
              "(:class:`eyestereo.hdl.interfaces.sram_bus.HostPort`): reads and posted writes, byte strobes 1..0",
}
WRITABLE = ("rw", "pulse", "array", "memory")


class RegisterMapError(ValueError):
    """The table is inconsistent (overlaps, fields outside the word, duplicate names, ...)."""


class RegisterIndexError(IndexError, ValueError):
    """A word index outside a register's words (a ValueError like every refused value; an IndexError as
    :meth:`Register.address` raised before)."""


def _is_bool(value) -> bool:
    """True for Python and numpy bools."""
    return isinstance(value, bool) or getattr(getattr(value, "dtype", None), "kind", None) == "b"


def _shown(value) -> str:
    """A refused value as a message shows it (integers in decimal, anything else by repr, kept short)."""
    if isinstance(value, numbers.Integral) and not _is_bool(value):
        return str(int(value))
    text = str(value) if isinstance(value, numbers.Number) or _is_bool(value) else repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


def _range(mask: int) -> str:
    """The values a mask allows, for a message: ``0..1048575, 20 bits`` or ``the fields' bits 0x303 only``."""
    if mask & (mask + 1) == 0:
        n = mask.bit_length()
        return f"0..{mask}, {n} bit{'s' if n != 1 else ''}"
    return f"the fields' bits {mask:#x} only"


def check_bits(value, mask: int, where: str) -> int:
    """``value`` as a Python int; ValueError unless it is an integer (Python or numpy; a bool only where
    ``mask`` is one bit; a float, even 2.0, is refused) that sets no bit outside ``mask``. The one-line
    message starts with ``where`` and gives the value and the range: ``THR_LEFT[3]: 1048576 does not fit
    (0..1048575, 20 bits)``. The check behind :meth:`Field.check` and :meth:`Register.check_value`."""
    if _is_bool(value) and mask != 1:
        raise ValueError(f"{where}: {_shown(value)} is a bool, not an integer ({_range(mask)})")
    if not (_is_bool(value) or isinstance(value, numbers.Integral)):
        raise ValueError(f"{where}: {_shown(value)} is not an integer ({_range(mask)})")
    v = int(value)
    if v < 0 or v & ~mask:
        raise ValueError(f"{where}: {v} does not fit ({_range(mask)})")
    return v


def _is_int(value) -> bool:
    return isinstance(value, numbers.Integral) and not _is_bool(value)


def check_frame_size(width, height) -> tuple[int, int]:
    """The register bank's ``width``/``height`` parameters as Python ints; ValueError unless each is an
    integer (numpy integers too; not a bool or a float) in :data:`FRAME_MIN`..:data:`FRAME_MAX`.

    The rule of :func:`eyestereo.hdl.system.register_bank.register_bank` (which calls this, its message then
    starting with ``register_bank: ``) and of its model, so that the model refuses exactly the banks that
    cannot be built; the range is the SRAM arbiter's (``hdl/memory/sram_arbiter.py``), whose frame the GEOMETRY
    register reports.
    """
    out = []
    for name, v in (("width", width), ("height", height)):
        allowed = f"the bank takes {FRAME_MIN}..{FRAME_MAX}"
        if not _is_int(v):
            raise ValueError(f"parameter {name} must be an integer, got {type(v).__name__} {_shown(v)} ({allowed})")
        v = int(v)
        if v < FRAME_MIN:
            raise ValueError(f"parameter {name}={v} is too small: {allowed}")
        if v > FRAME_MAX:
            raise ValueError(f"parameter {name}={v} is too large: {allowed}")
        out.append(v)
    return out[0], out[1]


@dataclass(frozen=True)
class Field:
    """A field of a register: bits ``lsb + width - 1 .. lsb``.

    ``reset``: value after reset (rw, const); ``param``: for a const, the bank's elaboration parameter
    that gives the value instead; ``values``: meaning of codes (documentation and the driver).
    """

    name: str
    lsb: int
    width: int
    doc: str
    reset: int = 0
    param: str | None = None
    values: tuple[tuple[int, str], ...] = ()
    #: where the field's port connects in the system top (documentation for whoever assembles it)
    connect: str = ""

    @property
    def mask(self) -> int:
        return ((1 << self.width) - 1) << self.lsb

    @property
    def bits(self) -> str:
        return f"{self.lsb}" if self.width == 1 else f"{self.lsb + self.width - 1}:{self.lsb}"

    def check(self, value, where: str | None = None) -> int:
        """``value`` as a Python int; ValueError unless it fits the field: an integer (Python or numpy; a
        bool only in a 1-bit field; a float, even 2.0, is refused) in 0..2**width-1. Nothing is masked:
        a code that does not fit would otherwise reach the hardware as another code (2**20 as threshold
        0). ``where`` names the field in the message (default: its name), e.g.
        ``K_LEFT.k_left: 256 does not fit (0..255, 8 bits)``."""
        return check_bits(value, (1 << self.width) - 1, where or self.name)


@dataclass(frozen=True)
class Register:
    """One register (or an aligned group of words: array, window, memory)."""

    name: str
    offset: int
    kind: str
    doc: str
    fields: tuple[Field, ...] = ()
    count: int = 1
    port: str | None = None    # array/window/memory: the bank's port for it
    latency: int = 0           # window: clocks from address to data on its port
    words: tuple[str, ...] = ()  # window: a name per word (driver and docs)

    @property
    def span(self) -> int:
        """Bytes the register's aligned region takes (a power of two of words)."""
        n = 1
        while n < self.count:
            n *= 2
        return 4 * n

    @property
    def mask(self) -> int:
        m = 0
        for f in self.fields:
            m |= f.mask
        return m

    def reset_value(self, params: dict | None = None) -> int:
        """The word a read returns after reset (inputs and windows: not defined by the table: 0)."""
        if self.kind not in ("const", "rw", "array"):
            return 0
        v = 0
        for f in self.fields:
            x = f.reset if f.param is None else int((params or {})[f.param])
            v |= (x & ((1 << f.width) - 1)) << f.lsb
        return v

    def address(self, index: int = 0) -> int:
        """Byte address of word ``index`` (:meth:`check_index` first)."""
        return self.offset + 4 * self.check_index(index)

    def label(self, index: int = 0) -> str:
        """How messages name word ``index``: ``CTRL``, ``THR_LEFT[3]``, ``SRAM word 0x12345``."""
        if self.kind == "memory":
            return f"{self.name} word {index:#x}"
        return self.name if self.count == 1 else f"{self.name}[{index}]"

    def check_index(self, index) -> int:
        """``index`` as a Python int; :class:`RegisterIndexError` (a ValueError and an IndexError) unless
        it is an integer in 0..count-1: ``THR_LEFT: index 16 is outside 0..15`` or, for the memory,
        ``SRAM word 0x100000 is outside the window (0..0xfffff)``."""
        if self.kind == "memory":
            what = f"{self.name} word {index:#x}" if _is_int(index) else f"{self.name} word {_shown(index)}"
            within, outside = f"the window is 0..{self.count - 1:#x}", f"the window (0..{self.count - 1:#x})"
        else:
            what = f"{self.name}: index {_shown(index)}"
            within = outside = f"0..{self.count - 1}"
        if not _is_int(index):
            raise RegisterIndexError(f"{what} is not an integer ({within})")
        if not 0 <= int(index) < self.count:
            raise RegisterIndexError(f"{what} is outside {outside}")
        return int(index)

    def check_words(self, first, count) -> range:
        """Word indices ``first`` .. ``first + count - 1`` (a run of memory or array words) as a range;
        :class:`RegisterIndexError` unless both are integers, ``count`` >= 0 and every word lies in
        0..count-1 (the message names the first word outside), checked before any word moves."""
        if not _is_int(count) or count < 0:
            raise RegisterIndexError(f"{self.name}: word count {_shown(count)} is not an integer >= 0")
        self.check_index(first)
        first, count = int(first), int(count)
        if first + count > self.count:
            try:
                self.check_index(self.count)
            except RegisterIndexError as e:
                start = f"{first:#x}" if self.kind == "memory" else str(first)
                raise RegisterIndexError(f"{e}; asked for {count} words from {start}") from None
        return range(first, first + count)

    def check_value(self, value, index=0) -> int:
        """The word ``value`` for word ``index`` as a Python int; ValueError unless the index is in
        0..count-1 and the value an integer that sets only the bits of the register's fields: 0..2**20-1
        for THR_LEFT, 0..255 for K_LEFT, 0..65535 for an SRAM word, CTRL's bits 0x303 (a read-only register
        takes any 32-bit word: the bank answers SLVERR). Floats (even 2.0) are refused, a bool only where
        the word is one bit; nothing is masked. E.g. ``THR_LEFT[3]: 1048576 does not fit (0..1048575, 20 bits)``."""
        index = self.check_index(index)
        mask = self.mask if self.kind in WRITABLE else 0xFFFFFFFF
        return check_bits(value, mask, self.label(index))


_SEQ = "the system's sequencer (issue 15 item 2)"


def _cell(text: str) -> str:
    """Text for a Markdown table cell (a '|' would end the cell)."""
    return str(text).replace("|", "\\|")


def _f(name, lsb, width, doc, **kw) -> Field:
    return Field(name, lsb, width, doc, **kw)


_DISP = "disparity_writer (stereo_frontend's dense option)"
_DENSE = "dense_stereo's port of the same name (stereo_frontend's dense option)"
_MATCH = "feature_matcher (stereo_frontend's matcher option):"


def _ctl(name, lsb, doc, width=1) -> Field:
    """A field wired to the arbiter's FrameControl member of the same name."""
    return Field(name, lsb, width, doc, connect=FRAME_CONTROL + name)


REGISTERS: tuple[Register, ...] = (
    Register("ID", 0x000, "const", "identification: 'ES' and the register map's version",
             (_f("id", 0, 32, "0x4553_0001: 'E' 'S', map version 1", reset=0x45530001),)),
    Register("GEOMETRY", 0x004, "const", "frame size the system was built for",
             (_f("width", 0, 16, "pixels per line", param="width"),
              _f("height", 16, 16, "lines per frame", param="height"))),
    Register("CTRL", 0x008, "rw", "operating mode and the host's hold on the rectified and feature buffers",
             (_f("mode", 0, 1, "0 sequential (one stage after the other), 1 overlapped (double buffers)",
                 values=((0, "sequential"), (1, "overlapped")), connect=_SEQ),
              _f("continuous", 1, 1, "0 single-shot (one stereo frame per start), 1 continuous (until stop)",
                 values=((0, "single-shot"), (1, "continuous")), connect=_SEQ),
              _ctl("rect_want", 8, "the host takes the newest rectified pair whenever it holds none "
                   "(FrameControl.rect_want)"),
              _ctl("feat_want", 9, "the same for the feature lists (FrameControl.feat_want)"),
              _f("disp_want", 10, 1, "the same for the disparity maps (dense option)", connect=_DISP))),
    Register("CMD", 0x00C, "pulse", "commands (write 1 to act; reads 0)",
             (_f("start", 0, 1, "start: one stereo frame (single-shot) or frames until stop (continuous)",
                connect=_SEQ),
              _f("stop", 1, 1, "stop after the frame in progress", connect=_SEQ),
              _ctl("rect_release", 8, "the host has read the rectified pair it holds (FrameControl.rect_release)"),
              _ctl("feat_release", 9, "the host has read the feature lists it holds (FrameControl.feat_release)"),
              _f("disp_release", 10, 1, "the host has read the disparity map it holds (dense option)", connect=_DISP))),
    Register("STATUS", 0x010, "status", "state of the system and of the frame buffers",
             (_f("busy", 0, 1, "a start is being served (single-shot: until its frame's lists are written)",
                connect=_SEQ),
              _ctl("avail", 4, "a FULL frame waits in camera 0, camera 1, rectified, features (bits 4..7; "
                   "FrameControl.avail)", width=4),
              _ctl("rect_held", 8, "the host holds a rectified pair (FrameControl.rect_held)"),
              _ctl("feat_held", 9, "the host holds the feature lists (FrameControl.feat_held)"),
              _f("disp_held", 10, 1, "the host holds a disparity map (dense option)", connect=_DISP),
              _f("disp_avail", 11, 1, "a complete disparity map waits (dense option)", connect=_DISP),
              _ctl("rect_buf", 12, "the rectified buffer held (0/1: its SRAM address, AddressMap.rectified)"),
              _ctl("feat_buf", 13, "the feature-list buffer held (AddressMap.features)"),
              _f("disp_buf", 14, 1, "the disparity buffer held (AddressMap.disparity)", connect=_DISP))),
    Register("K_LEFT", 0x014, "rw", "Harris k of the left camera, ufix[8,8] (k = code / 256)",
             (_f("k_left", 0, K_BITS, "k code (reset: 10, k = 0.039)", reset=K_RESET,
                 connect="the left Harris k port, through a word_cdc into the Harris clock"),)),
    Register("K_RIGHT", 0x018, "rw", "Harris k of the right camera",
             (_f("k_right", 0, K_BITS, "k code (reset: 10)", reset=K_RESET,
                 connect="the right Harris k port, through a word_cdc"),)),
    Register("FRAMES", 0x020, "status", "stereo frames completed since reset (both feature lists written)",
             (_f("frames", 0, 32, "count, wraps", connect=_SEQ),)),
    Register("FEATURES", 0x024, "status", "features found in the last completed frame, per camera",
             (_f("features_left", 0, 16, "left camera",
                 connect="feature_list total_left (stereo_frontend runs feature_list in the memory clock)"),
              _f("features_right", 16, 16, "right camera",
                 connect="feature_list total_right"))),
    Register("DROPPED", 0x028, "status", "camera frames dropped (camera_interface's counters; rectify=stream: "
             "plus each frame the rectifier found overwritten, once)",
             (_f("dropped_left", 0, 16, "left camera", connect="camera_pair dropped_l (already in the memory clock)"),
              _f("dropped_right", 16, 16, "right camera", connect="camera_pair dropped_r"))),
    Register("OVERFLOWS", 0x02C, "status", "frames lost to overflows after the cameras",
             (_f("harris_overflows", 0, 16, "stereo frames cut crossing into the Harris clock",
                 connect="stream_cdc dropped: the crossing into the Harris clock (back through a word_cdc) plus the "
                         "flags' crossing back"),
              _f("list_overflows", 16, 16,
                 "completed frames whose feature list was cut at max_features (its trailer's overflow flag)",
                 connect=_SEQ + " (counts the lists flagged overflowed in ARB words 20, 21)"))),
    Register("FRAME_CLOCKS", 0x030, "status", "memory clocks the last completed frame took from its start "
             "(frames/s = 100e6 / value)", (_f("frame_clocks", 0, 32, "clocks", connect=_SEQ),)),
    Register("DENSE", 0x034, "rw", "the dense option's run-time settings (sgm's ports; no effect without the option)",
             (_f("p1", 0, 8, "SGM penalty P1 for a disparity step of 1 (reset: 10)", reset=DENSE_DEFAULTS["p1"],
                 connect=_DENSE),
              _f("p2", 8, 8, "SGM penalty P2 for larger steps (reset: 30)", reset=DENSE_DEFAULTS["p2"],
                 connect=_DENSE),
              _f("uniqueness", 16, 7, "uniqueness margin in percent (reset: 10)",
                 reset=DENSE_DEFAULTS["uniqueness"], connect=_DENSE),
              _f("lr_check", 24, 1, "left-right consistency check on (reset: 1)",
                 reset=int(DENSE_DEFAULTS["lr_check"]), connect=_DENSE),
              _f("subpixel", 25, 1, "sub-pixel refinement on (reset: 1)", reset=int(DENSE_DEFAULTS["subpixel"]),
                 connect=_DENSE))),
    Register("DENSE_STATUS", 0x038, "status", "the dense option's state (reads 0 without the option)",
             (_f("disp_frames", 0, 16, "disparity maps completed since reset (wraps)", connect=_DISP),
              _f("dense_overrun", 16, 1, "the sgm input FIFO lost a pixel since reset (sticky; the front end paces "
                 "the rectifier so that it should never be set)", connect=_DENSE),
              _f("disp_lost", 17, 1, "a disparity code found the writer's FIFO full (sticky: the memory did not keep "
                 "up)", connect=_DISP))),
    Register("MATCH", 0x03C, "rw", "the matcher option's run-time settings (feature_matcher's ports; no effect "
             "without the option)",
             (_f("match_limit", 0, 13, "a best cost is accepted below this (reset: 891 = 11 x 81, SAD 9 x 9 with "
                 "t_max 11; census: ceil(h_max (window**2 - 1) / 100), 12 for 9 x 9 at 15 %)", reset=11 * 81,
                 connect=_MATCH + " limit"),
              _f("match_uniqueness", 16, 7, "uniqueness in percent, 0 off, at most 99 (reset: 0)", reset=0,
                 connect=_MATCH + " uniqueness"),
              _f("match_lr_check", 24, 1, "left-right check on (reset: 1)", reset=1, connect=_MATCH + " lr_check"))),
    Register("MATCH_STATUS", 0x040, "status", "the matcher option's last list and faults (reads 0 without it)",
             (_f("matches", 0, 15, "matches in the last match list written (its trailer's count)",
                 connect="list_append count"),
              _f("match_overflow", 15, 1, "that list was cut at max_matches", connect="list_append overflow"),
              _f("match_dropped", 16, 1, "the match engine could not keep a corner, a row end or a left corner "
                 "since reset (sticky; the lists are not the model's then)", connect=_MATCH + " dropped"))),
    Register("MATCH_FAULTS", 0x044, "status", "corners the matcher skipped since reset (reads 0 without it)",
             (_f("match_late", 0, 16, "corners whose flag came after their window had left the line buffers",
                 connect=_MATCH + " late"),
              _f("match_lost", 16, 16, "corners that found the pending queue full", connect=_MATCH + " lost"))),
    Register("LOST", 0x048, "status", "frames the sequencer gave up",
             (_f("lists_lost", 0, 16, "rectified frames whose feature lists never came (a Harris-domain reset cut "
                 "them): given up by the sequencer's list watchdog after list_timeout clocks",
                 connect=_SEQ + " lists_lost"),)),
    Register("THR_LEFT", 0x100, "array", "pre-threshold of each 4x4 block of the left image, index by*4 + bx "
             "(20-bit cornerness code; 0 after reset)",
             (_f("thr_left", 0, THRESHOLD_BITS, "threshold code",
                 connect="the left pre-threshold's thr_we/thr_addr/thr_data, through a stream_cdc (24-bit "
                         "one-beat frames) into the Harris clock"),),
             count=16, port="thr_left"),
    Register("THR_RIGHT", 0x140, "array", "the same for the right image",
             (_f("thr_right", 0, THRESHOLD_BITS, "threshold code",
                 connect="the right pre-threshold's write port, the same way"),),
             count=16, port="thr_right"),
    Register("FCOUNT", 0x180, "window", "features per block in the last completed frame: left blocks 0..15, "
             "right blocks 16..31 (read port addr = camera << 4 | block)",
             (_f("fcount", 0, 16, "features in the block",
                 connect="feature_list's per-block counters (memory clock): count_addr = block << 1 | camera, "
                         "two registers for the window's latency of 2"),),
             count=32, port="fcount", latency=2, words=tuple(f"{c}{b}" for c in ("left", "right") for b in range(16))),
    Register("ARB", 0x200, "window", "the SRAM arbiter's status words (its status port, STAT in "
             "eyestereo.tools.models.sram_arbiter): words moved and clocks waited per master, frames per buffer",
             (_f("arb", 0, 32, "status word", connect="sram_subsystem stat (StatPort)"),),
             count=len(ARB_WORDS), port="arb", latency=2, words=ARB_WORDS),
    Register("SRAM", 0x400000, "memory", "the SRAM, one 16-bit word per bus word (bits 15..0; 31..16 read 0); "
             "frame buffers at eyestereo.tools.models.sram_arbiter.AddressMap",
             (_f("data", 0, 16, "SRAM word", connect="sram_subsystem host (HostPort)"),), count=1 << 20, port="host"),
)


@dataclass(frozen=True)
class RegisterMap:
    """A checked register table with look-ups by name and by address."""

    registers: tuple[Register, ...]
    #: the bank's local register space (bytes; everything but memory lies below it)
    local_bytes: int = 0x400
    names: dict = field(init=False, repr=False, compare=False)
    fields: dict = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        names, fields = {}, {}
        spans = []
        for r in self.registers:
            if r.kind not in KINDS:
                raise RegisterMapError(f"register {r.name}: unknown kind {r.kind!r} (kinds: {', '.join(KINDS)})")
            if not r.name.isidentifier() or r.name in names:
                raise RegisterMapError(f"register name {r.name!r} is not a unique identifier")
            if r.offset % r.span:
                raise RegisterMapError(f"register {r.name} at {r.offset:#x} is not aligned to its {r.span} bytes")
            if (r.count > 1) != (r.kind in ("array", "window", "memory")):
                raise RegisterMapError(f"register {r.name}: only arrays, windows and memories have count > 1")
            if (r.port is None) == (r.kind in ("array", "window", "memory")):
                raise RegisterMapError(f"register {r.name}: arrays, windows and memories (only) name a port")
            if r.kind != "memory" and r.offset + r.span > self.local_bytes:
                raise RegisterMapError(f"register {r.name} lies outside the local space (< {self.local_bytes:#x})")
            if r.kind == "window" and (r.latency < 1 or len(r.words) != r.count):
                raise RegisterMapError(f"window {r.name} needs a latency >= 1 and a name per word")
            if not r.fields:
                raise RegisterMapError(f"register {r.name} has no field")
            if r.kind in ("array", "window", "memory") and (len(r.fields) != 1 or r.fields[0].lsb != 0):
                raise RegisterMapError(f"register {r.name}: an {r.kind} has one field from bit 0")
            used = 0
            for f in r.fields:
                if f.width < 1 or f.lsb < 0 or f.lsb + f.width > 32:
                    raise RegisterMapError(f"field {r.name}.{f.name} (bits {f.bits}) is outside the 32-bit word")
                if used & f.mask:
                    raise RegisterMapError(f"field {r.name}.{f.name} overlaps another field")
                used |= f.mask
                if not 0 <= f.reset < (1 << f.width):
                    raise RegisterMapError(f"field {r.name}.{f.name}: reset {f.reset} does not fit {f.width} bits")
                if f.param is not None and r.kind != "const":
                    raise RegisterMapError(f"field {r.name}.{f.name}: only constants take a parameter")
                if not f.name.isidentifier() or f.name in fields:
                    raise RegisterMapError(f"field name {f.name!r} is not a unique identifier (it names a port)")
                fields[f.name] = (r, f)
            names[r.name] = r
            spans.append((r.offset, r.offset + (r.span if r.kind != "memory" else 4 * r.count), r.name))
        spans.sort()
        for (_, a1, n0), (b0, _, n1) in zip(spans, spans[1:]):
            if b0 < a1:
                raise RegisterMapError(f"registers {n0} and {n1} overlap")
        object.__setattr__(self, "names", names)
        object.__setattr__(self, "fields", fields)

    def __iter__(self):
        return iter(self.registers)

    def __getitem__(self, name: str) -> Register:
        return lookup(self.names, name, "the register map has no register", KeyError)

    def field(self, name: str) -> tuple[Register, Field]:
        """(register, field) of a field name (``"mode"`` or ``"CTRL.mode"``)."""
        reg, _, fname = name.rpartition(".")
        if fname not in self.fields or (reg and self.fields[fname][0].name != reg):
            raise KeyError(f"no field {name!r}; fields: {', '.join(self.fields)}")
        return self.fields[fname]

    @property
    def addr_bits(self) -> int:
        """Byte-address bits of the bus (the memory window's end)."""
        end = max(r.offset + (4 * r.count if r.kind == "memory" else r.span) for r in self.registers)
        return (end - 1).bit_length()

    def decode(self, address: int) -> tuple[Register, int] | None:
        """(register, word index) at a byte address, or None where nothing is mapped."""
        a = int(address) & ~3
        for r in self.registers:
            if r.offset <= a < r.offset + 4 * r.count:
                return r, (a - r.offset) // 4
        return None

    def of_kind(self, *kinds: str) -> list[Register]:
        return [r for r in self.registers if r.kind in kinds]

    # ---- documentation -------------------------------------------------------------------------------
    def table_md(self) -> str:
        """The register table (one line per register) in Markdown."""
        out = ["| offset | name | kind | reset | fields | what |", "|---|---|---|---|---|---|"]
        for r in self.registers:
            last = r.offset + 4 * (r.count - 1)
            where = f"`{r.offset:#05x}`" if r.count == 1 else f"`{r.offset:#05x}`..`{last:#05x}`"
            if r.kind == "const" and any(f.param for f in r.fields):
                reset = "parameters"
            elif r.kind in ("const", "rw", "array"):
                reset = f"`{r.reset_value():#x}`"
            else:
                reset = "-"
            flds = ", ".join(f"{f.name}[{f.bits}]" for f in r.fields)
            out.append(f"| {where} | {r.name} | {r.kind}{'' if r.count == 1 else f' x {r.count}'} | {reset} | "
                       f"{flds} | {_cell(r.doc)} |")
        return "\n".join(out)

    def document(self) -> str:
        """docs/registers.md."""
        out = ["# Register map", "",
               "What the processor sees on the register bus: AXI4-Lite, 32-bit data, "
               f"{self.addr_bits}-bit byte addresses (`eyestereo.hdl.interfaces.axil`; timing in docs/timing.md). "
               "Generated by `make regs` (`python -m eyestereo.tools.regmap`) from `tools/regmap.py`, the one "
               "description from which the register bank (`hdl/system/register_bank.py`), the host driver "
               "(`tools/host_driver.py`) and the bank's model come; edit that table, not this file.", "",
               "## Registers", "", self.table_md(), "",
               "## Kinds", "", "| kind | behaviour |", "|---|---|"]
        out += [f"| {k} | {v} |" for k, v in KINDS.items()]
        out += ["", "## Bus behaviour", "",
                "* Byte addresses; the low two bits are ignored (every access is a whole word, `wstrb` selects "
                "the bytes a write changes).",
                "* A write to a `rw` register changes the bytes with `wstrb` set; bits outside its fields read 0. "
                "A write to an `array` word does the same on its stored copy and passes the new word to the "
                "write port. A write to `CMD` acts on the 1 bits of the bytes with `wstrb` set.",
                "* OKAY for every mapped access; SLVERR (read data 0, nothing changes) for an address where "
                "nothing is mapped (including the unused words of a window) and for a write to a `const`, "
                "`status` or `window` register. `CMD` reads 0 with OKAY.",
                "* `SRAM`: a write with `wstrb[1:0]` = 0 changes nothing (OKAY); the SRAM is written with "
                "byte enables `wstrb[1:0]` and the response comes when the arbiter has taken the write "
                "(posted: a later read of the same word returns it). A read waits for the arbiter.",
                "* One access at a time: reads and writes alternate when both wait.", ""]
        out += ["## Connections in the system top", "",
                "The bank runs in one clock (the memory clock, 100 MHz, like the arbiter's status and host "
                "ports); ports that belong to another clock domain say how to cross.", "",
                "| bank port | direction | connects to |", "|---|---|---|"]
        for r in self.registers:
            for f in r.fields:
                if r.kind == "const":
                    continue
                if r.kind in ("rw", "pulse", "status"):
                    port, d = f"regs_{f.name}", "in" if r.kind == "status" else "out"
                elif r.kind == "array":
                    port, d = f"regs_{r.port}_we/_addr/_data", "out"
                elif r.kind == "window":
                    port, d = f"{r.port}_addr / {r.port}_data", "out / in"
                else:
                    port, d = f"{r.port}_req_* / {r.port}_rsp_*", "out / in"
                out.append(f"| `{port}` | {d} | {_cell(f.connect)} |")
        out += ["", "## Fields", ""]
        for r in self.registers:
            out += [f"### {r.name} (`{r.offset:#05x}`, {r.kind})", "", r.doc, "",
                    "| bits | field | reset | what |", "|---|---|---|---|"]
            for f in r.fields:
                reset = f"parameter {f.param}" if f.param else (f"{f.reset:#x}" if r.kind in ("rw", "const",
                                                                                        "array") else "-")
                vals = "; ".join(f"{v}: {t}" for v, t in f.values)
                what = _cell(f.doc) + (f" ({vals})" if vals else "")
                out.append(f"| {f.bits} | {f.name} | {reset} | {what} |")
            if r.words and r.kind == "window":
                out += ["", "Words: " + ", ".join(f"{i} `{w}`" for i, w in enumerate(r.words)) + "."]
            out.append("")
        return "\n".join(out)


REGMAP = RegisterMap(REGISTERS)

README_BEGIN, README_END = "<!-- regs:begin -->", "<!-- regs:end -->"


def readme_section(text: str, regmap: RegisterMap = REGMAP) -> str:
    """README text with the register table between the markers replaced."""
    i, j = text.find(README_BEGIN), text.find(README_END)
    if i < 0 or j < i:
        raise RegisterMapError(f"README has no {README_BEGIN} ... {README_END} section")
    return text[:i + len(README_BEGIN)] + "\n" + regmap.table_md() + "\n" + text[j:]


def main(argv=None) -> int:
    from eyestereo.tools.io import atomic_write_text

    root = Path(__file__).resolve().parent.parent
    ap = argparse.ArgumentParser(description="Write docs/registers.md and README's register table from the "
                                             "register map.")
    ap.add_argument("--doc", type=Path, default=root / "docs" / "registers.md")
    ap.add_argument("--readme", type=Path, default=root / "README.md")
    args = ap.parse_args(argv)
    try:
        readme = readme_section(args.readme.read_text())
    except (OSError, RegisterMapError) as e:
        print(f"make regs: {e}", file=sys.stderr)
        return 1
    atomic_write_text(args.doc, REGMAP.document())
    atomic_write_text(args.readme, readme)
    print(args.doc)
    print(args.readme)
    return 0


if __name__ == "__main__":
    sys.exit(main())
