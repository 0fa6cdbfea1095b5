"""The OmniVision OV7670's start-up register table (QVGA, YUV 4:2:2, 30 frames/s from a 25 MHz XCLK), its
identification registers, its QVGA bus timing, and a loader for a user's own table.

Sources (cited by the short names used in the comments below):

* [DS] OmniVision, "OV7670/OV7171 CMOS VGA (640x480) CameraChip Sensor with OmniPixel Technology",
  data sheet v1.4 (2006): the register set (Table 5), the SCCB timing (Table 6, the figure "SCCB timing
  diagram") and the frame timing figures (VGA: a line of 784 pixel times, 510 lines).
* [IG] OmniVision, "OV7670/OV7171 CMOS VGA CameraChip Implementation Guide" v1.0 (2005): the format and
  scaling settings (QVGA through the DCW down-sampler), the clock set-up and frame-rate formula, the
  colour matrix for YUV output, gamma and the reserved registers it asks to be set.
* [SCCB] OmniVision, "Serial Camera Control Bus Functional Specification" v2.2 (2007): the protocol
  (3-phase write, 2-phase write + 2-phase read, the 9th bit of a phase "don't care" / "NA").

The table is what :func:`eyestereo.hdl.camera.sccb_master.sccb_master` writes into both sensors at start-up;
a user's own table comes from a text file (:func:`load_table`). An entry is ``(reg, value)``; ``reg`` =
:data:`DELAY` means "wait ``value`` milliseconds" (the sensor needs about 1 ms after the soft reset
``COM7 = 0x80`` before it takes the next write [IG]; 0xFF is no register of the OV7670: [DS] Table 5 ends at
0xC9).

What the front end expects (``hdl/interfaces/camera_bus.py``, ``camera_stream``'s defaults): YUV 4:2:2 in the
byte order ``YUYV`` (:data:`eyestereo.tools.camera.ORDERS`), VSYNC and HREF active high, data changing after
PCLK's falling edge (sampled on the rising edge), PCLK free-running: ``camera_stream`` runs on PCLK itself,
so PCLK must not stop in the blanking (COM10[5] = 0).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path

from eyestereo.tools.camera import CameraTiming

__all__ = ["DELAY", "PID", "PID_VALUE", "VER", "VER_VALUE", "ID_WRITE", "ID_READ", "COM7", "COM7_RESET", "ENTRIES",
           "TABLE", "RESET_WAIT_S", "XCLK_HZ", "QvgaTiming", "QVGA", "check_table", "load_table", "parse_table"]

#: The table's delay entry: ``(DELAY, ms)`` waits ``ms`` milliseconds (1..255).
DELAY = 0xFF
#: Product ID and version registers and their values [DS] Table 5: PID 0x76, VER 0x73 ("7673").
PID, PID_VALUE = 0x0A, 0x76
VER, VER_VALUE = 0x0B, 0x73
#: SCCB slave IDs [DS], [SCCB]: 0x42 for writes, 0x43 for reads (7-bit address 0x21 with the R/W bit).
ID_WRITE, ID_READ = 0x42, 0x43
#: COM7 and its soft-reset bit [DS]: bit 7 resets every register to its default.
COM7, COM7_RESET = 0x12, 0x80
#: How long the sensor needs after a soft reset before the next SCCB access [IG] (the slave model checks it).
RESET_WAIT_S = 1e-3
#: The ULX3S's oscillator, fed to both sensors' XCLK.
XCLK_HZ = 25e6

#: (reg, value, what it does): QVGA 320x240, YUV 4:2:2 YUYV, 30.0 frames/s from XCLK = 25 MHz.
ENTRIES: tuple[tuple[int, int, str], ...] = (
    (0x12, 0x80, "COM7: soft reset, every register back to its default [DS]"),
    (DELAY, 2, "wait 2 ms: twice the 1 ms the sensor needs after the reset [IG]"),
    # clock: PCLK = XCLK / (CLKRC[5:0] + 1) with the PLL bypassed; the DCW scaler halves it in QVGA
    (0x11, 0x00, "CLKRC: internal clock = XCLK / 1 = 25 MHz [DS]"),
    (0x6B, 0x0A, "DBLV: PLL bypassed, internal regulator on [DS]"),
    # format: QVGA YUV from the VGA array through the down-sampler [IG] 'QVGA' settings
    (0x12, 0x10, "COM7: QVGA, YUV output (bits 2 and 0 clear) [DS]"),
    (0x0C, 0x04, "COM3: DCW (down-sampling) enable, the QVGA scaler needs it [IG]"),
    (0x3E, 0x19, "COM14: DCW and scaling PCLK enable, manual scaling, PCLK divided by 2 [IG]"),
    (0x70, 0x3A, "SCALING_XSC: horizontal scale factor, no test pattern [IG]"),
    (0x71, 0x35, "SCALING_YSC: vertical scale factor, no test pattern [IG]"),
    (0x72, 0x11, "SCALING_DCWCTR: down-sample by 2 horizontally and vertically [IG]"),
    (0x73, 0xF1, "SCALING_PCLK_DIV: DSP clock divided by 2 (matches COM14) [IG]"),
    (0xA2, 0x02, "SCALING_PCLK_DELAY: scaling output delay of 2 [IG]"),
    # the output window of QVGA [IG]: HSTART/HSTOP/HREF and VSTRT/VSTOP/VREF as a group
    (0x17, 0x16, "HSTART: horizontal frame start, high 8 bits [IG]"),
    (0x18, 0x04, "HSTOP: horizontal frame end, high 8 bits (wraps past the line end) [IG]"),
    (0x32, 0xA4, "HREF: HREF edge offset 2 (bits 7:6), low 3 bits of HSTOP and HSTART (4, 4): the window "
                 "(0x16 << 3 | 4) + 640 = (0x04 << 3 | 4) mod 784 [IG]"),
    (0x19, 0x02, "VSTRT: vertical frame start, high 8 bits [IG]"),
    (0x1A, 0x7A, "VSTOP: vertical frame end, high 8 bits [IG]"),
    (0x03, 0x0A, "VREF: low 2 bits of VSTRT/VSTOP [IG]"),
    # the bus as camera_stream expects it
    (0x15, 0x00, "COM10: VSYNC and HREF active high, HREF (not HSYNC), PCLK free-running, data after PCLK's "
                 "falling edge [DS]"),
    (0x3A, 0x04, "TSLB: bit 3 = 0 (Y before chroma, with COM13[0]), fixed window off [DS], [IG]"),
    (0x3D, 0xC0, "COM13: gamma on, UV saturation auto, bit 0 = 0 (U before V): byte order Y U Y V [DS]"),
    (0x40, 0xC0, "COM15: output range 0x00..0xFF [DS]"),
    (0x04, 0x00, "COM1: no CCIR656 (separate HREF/VSYNC), AEC low bits 0 [DS]"),
    # frame rate: the QVGA frame is 510 rows of 784 PCLK at 12.5 MHz (31.3 frames/s); 21 dummy rows make it 30.0
    (0x92, 0x15, "DM_LNL: 21 dummy rows in the vertical blanking, 531 rows: 30.03 frames/s [DS]"),
    (0x93, 0x00, "DM_LNH: dummy rows, high byte 0 [DS]"),
    # automatic exposure, gain and white balance [IG]
    (0x13, 0xE7, "COM8: fast AEC, unlimited AEC step, banding filter, AGC, AWB and AEC on [DS]"),
    (0x14, 0x18, "COM9: automatic gain ceiling 4x [DS]"),
    (0x24, 0x95, "AEW: AGC/AEC upper limit of the stable range [IG]"),
    (0x25, 0x33, "AEB: AGC/AEC lower limit of the stable range [IG]"),
    (0x26, 0xE3, "VPT: AGC/AEC fast-mode region [IG]"),
    # colour matrix for YUV (U = -0.169 R ... as [IG]'s YUV matrix), its signs in MTXS
    (0x4F, 0x80, "MTX1: colour matrix coefficient 1 [IG]"),
    (0x50, 0x80, "MTX2: colour matrix coefficient 2 [IG]"),
    (0x51, 0x00, "MTX3: colour matrix coefficient 3 [IG]"),
    (0x52, 0x22, "MTX4: colour matrix coefficient 4 [IG]"),
    (0x53, 0x5E, "MTX5: colour matrix coefficient 5 [IG]"),
    (0x54, 0x80, "MTX6: colour matrix coefficient 6 [IG]"),
    (0x58, 0x9E, "MTXS: matrix signs and auto contrast centre [IG]"),
    (0xB0, 0x84, "reserved register [IG] asks to set: without it the colours come out wrong"),
)

#: The table as the master takes it: (reg, value) pairs, delays included.
TABLE: tuple[tuple[int, int], ...] = tuple((r, v) for r, v, _ in ENTRIES)


@dataclass(frozen=True)
class QvgaTiming:
    """The DVP timing of QVGA with :data:`TABLE`, in PCLK periods (PCLK = XCLK / 2 = 12.5 MHz).

    From [DS]'s VGA frame (784 pixel times a row, 510 rows: VSYNC 3 rows, 17 rows to the first HREF, 480
    rows of HREF, 10 after) with [IG]'s QVGA down-sampler: PCLK halves, so a row is 784 PCLK, and HREF
    carries 320 pixels x 2 bytes = 640 PCLK on every other row (240 lines); DM_LNL adds 21 rows. The
    every-other-row HREF is our reading of the down-sampler; to be confirmed on a board with a logic
    analyser (every figure is a field).
    """

    row_pclk: int = 784
    href_pclk: int = 640
    href_every: int = 2
    vsync_rows: int = 3
    back_rows: int = 17
    rows: int = 510
    dummy_rows: int = 21
    width: int = 320
    height: int = 240

    @property
    def line_pclk(self) -> int:
        """PCLK from one HREF's start to the next."""
        return self.row_pclk * self.href_every

    @property
    def vsync_pclk(self) -> int:
        return self.vsync_rows * self.row_pclk

    @property
    def frame_pclk(self) -> int:
        return (self.rows + self.dummy_rows) * self.row_pclk

    def fps(self, pclk_hz: float = XCLK_HZ / 2) -> float:
        return pclk_hz / self.frame_pclk

    def camera_timing(self) -> CameraTiming:
        """The nearest :class:`~eyestereo.tools.camera.CameraTiming` (whole line periods of
        :attr:`line_pclk`) for the camera models: VSYNC rounded up to 2 line periods (3 rows are 1.5), the
        rest of the frame's rows split before and after the lines as [DS]'s VGA frame splits them."""
        lines = math.ceil(self.frame_pclk / self.line_pclk)
        v_sync = math.ceil(self.vsync_rows / self.href_every)
        v_back = math.ceil((self.vsync_rows + self.back_rows) / self.href_every) - v_sync
        return CameraTiming(width=self.width, height=self.height, h_blank=self.line_pclk - self.href_pclk,
                            v_sync=v_sync, v_back=v_back, v_front=lines - v_sync - v_back - self.height)


#: The QVGA timing of :data:`TABLE`.
QVGA = QvgaTiming()


def check_table(table) -> tuple[tuple[int, int], ...]:
    """A register table as (reg, value) int pairs: reg 0x00..0xFE with a value 0x00..0xFF, or
    ``(DELAY, ms)`` with 1..255 ms; at least one entry. Raises a one-line ValueError naming the entry."""
    if isinstance(table, (str, bytes)) or not hasattr(table, "__iter__"):
        raise ValueError(f"table must be a sequence of (reg, value) pairs, got {type(table).__name__}")
    out = []
    for i, e in enumerate(table):
        try:
            reg, value = e
        except (TypeError, ValueError):
            raise ValueError(f"table entry {i} must be a (reg, value) pair, got {e!r}") from None
        for name, x in (("reg", reg), ("value", value)):
            if isinstance(x, bool) or not isinstance(x, int) and not hasattr(x, "__index__"):
                raise ValueError(f"table entry {i}: {name} must be an integer, got {x!r}")
        reg, value = int(reg), int(value)
        if not 0 <= reg <= 0xFF:
            raise ValueError(f"table entry {i}: register {reg:#x} is not a byte")
        if reg == DELAY:
            if not 1 <= value <= 255:
                raise ValueError(f"table entry {i}: a delay is 1..255 ms, got {value}")
        elif not 0 <= value <= 0xFF:
            raise ValueError(f"table entry {i}: value {value:#x} of register {reg:#04x} is not a byte")
        out.append((reg, value))
    if not out:
        raise ValueError("table is empty: give at least one (reg, value) entry")
    return tuple(out)


_HEX = re.compile(r"^(?:0x)?([0-9a-f]{1,2})$", re.I)


def parse_table(text: str, source: str = "table") -> tuple[tuple[int, int], ...]:
    """A table from text: one entry a line, ``REG VALUE`` in hex (``12 80`` or ``0x12 0x80``), or
    ``delay MS`` (decimal milliseconds); ``#`` starts a comment; blank lines are skipped. A bad line gives
    a one-line ValueError: ``source:line: what is wrong``."""
    out = []
    for n, raw in enumerate(text.splitlines(), 1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        words = line.replace(",", " ").split()
        where = f"{source}:{n}"
        if len(words) != 2:
            raise ValueError(f"{where}: expected 'REG VALUE' (hex) or 'delay MS', got {line!r}")
        a, b = words
        if a.lower() == "delay":
            if not b.isdigit() or not 1 <= int(b) <= 255:
                raise ValueError(f"{where}: a delay is 1..255 ms (decimal), got {b!r}")
            out.append((DELAY, int(b)))
            continue
        ma, mb = _HEX.match(a), _HEX.match(b)
        if ma is None or mb is None:
            bad = a if ma is None else b
            raise ValueError(f"{where}: {bad!r} is not a hex byte (00..ff, optionally 0x)")
        reg, value = int(ma.group(1), 16), int(mb.group(1), 16)
        if reg == DELAY:
            raise ValueError(f"{where}: register 0xff is the delay entry; write 'delay MS' instead")
        out.append((reg, value))
    if not out:
        raise ValueError(f"{source}: no entries (one 'REG VALUE' in hex a line)")
    return tuple(out)


def load_table(path) -> tuple[tuple[int, int], ...]:
    """:func:`parse_table` of a text file (errors name the file and the line)."""
    p = Path(path)
    try:
        text = p.read_text()
    except OSError as e:
        raise ValueError(f"{p}: cannot read the register table ({e.strerror or e})") from None
    except UnicodeDecodeError:
        raise ValueError(f"{p}: not a text file") from None
    return parse_table(text, str(p))
