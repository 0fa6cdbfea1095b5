"""A DVI receiver in Python: three TMDS bit streams in, the frames and the sync timing they carry out.

It does what a monitor's receiver does, and checks what a monitor would silently forgive:

1. **Symbol boundary**: for each channel, of the ten bit offsets the one where the stream falls into runs
   of identical control characters (the blanking's; a control character is never a shift of a run of
   another, so one offset wins). A real receiver slips its bit clock until it sees them.
2. **Channel deskew**: the channels' characters are lined up on their first control-to-data edge (DE
   rises on all three in the same character).
3. **Decoding and rules**: every character is a control code or exactly the data character a DVI 1.0
   encoder sends for its byte at the running disparity so far (the disparity restarts at 0 in every control
   period, so it is known from the first control character on); DE is the same on the three channels;
   channels 1 and 2 send CTL0..CTL3 = 0 (DVI reserves them); channel 0's control codes are (HSYNC, VSYNC).
4. **Timing**: every DE run is ``h_active`` characters, every horizontal sync ``h_sync`` wide and
   ``h_total`` after the last, DE begins ``h_sync + h_back`` after a horizontal sync begins and the next
   one begins ``h_front`` after DE ends, a vertical sync lasts ``v_sync`` lines and begins with a
   horizontal sync, and a frame has ``v_active`` DE runs, the first ``v_back`` lines after the vertical
   sync, the last ``v_front`` lines before the next. The first breach raises :class:`DviError` naming the
   channel, the character (and its bit position) and what the mode says.

Frames are the ones received whole: after a vertical sync's leading edge, all ``v_active`` lines. Pixels are
RGB (channel 2 red, 1 green, 0 blue).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from eyestereo.tools.models.tmds_encoder import CONTROL, DISPARITY_BOUND, decode, encode
from eyestereo.tools.models.video_timing import VideoMode, mode_of

__all__ = ["DviError", "DviCapture", "receive", "align", "characters", "MIN_RUN"]

#: The shortest run of one control character that counts as a blanking period when aligning.
MIN_RUN = 8


class DviError(ValueError):
    """A stream no DVI transmitter of the mode sends (the message says where and why)."""


@dataclass
class DviCapture:
    frames: list[np.ndarray]  # HxWx3 uint8, RGB, the whole frames received, in order
    offsets: tuple[int, ...]  # per channel: the bit of its first whole character
    skew: tuple[int, ...]  # per channel: characters dropped to line the channels up
    timing: dict = field(default_factory=dict)  # what the stream showed (characters; v_* in lines)
    characters: int = 0  # characters per channel after alignment


def characters(bits, offset: int) -> np.ndarray:
    """The 10-bit characters of a bit stream from bit ``offset`` (bit 0 of a character first)."""
    b = np.asarray(bits, dtype=np.int64).ravel()[offset:]
    n = len(b) // 10
    return (b[:n * 10].reshape(n, 10) << np.arange(10)).sum(axis=1)


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """(start, end) of every run of True (end exclusive)."""
    m = np.concatenate([[False], np.asarray(mask, dtype=bool), [False]])
    d = np.diff(m.astype(np.int8))
    return list(zip(np.nonzero(d == 1)[0].tolist(), np.nonzero(d == -1)[0].tolist(), strict=True))


def align(bits, channel: int = 0) -> int:
    """The bit offset (0..9) of the stream's character boundary, from its runs of control characters."""
    score = []
    for off in range(10):
        c = characters(bits, off)
        total = 0
        for q in CONTROL:
            total += sum(e - s for s, e in _runs(c == q) if e - s >= MIN_RUN)
        score.append(total)
    best = int(np.argmax(score))
    if score[best] == 0:
        raise DviError(f"channel {channel}: no symbol boundary found: at none of the 10 bit offsets does the "
                       f"stream hold a run of {MIN_RUN} equal control characters (no blanking period)")
    if score.count(score[best]) > 1:
        raise DviError(f"channel {channel}: symbol boundary ambiguous: bit offsets "
                       f"{[i for i, s in enumerate(score) if s == score[best]]} see as many control characters")
    return best


# (disparity, byte) -> (character, next disparity), and character -> byte, as tables for speed
_CNTS = range(-DISPARITY_BOUND, DISPARITY_BOUND + 1)
_ENC = {cnt: [encode(d, cnt) for d in range(256)] for cnt in _CNTS if cnt % 2 == 0}
_DEC = [decode(q) for q in range(1024)]
_CTRL = {q: i for i, q in enumerate(CONTROL)}


def _check_characters(chars: np.ndarray, channel: int, where) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(is data, byte, control value c1 << 1 | c0) per character, every data character checked against the
    encoder from the first control character on."""
    n = len(chars)
    is_data = np.zeros(n, dtype=bool)
    byte = np.zeros(n, dtype=np.int64)
    ctrl = np.full(n, -1, dtype=np.int64)
    cnt = None  # unknown until the first control period
    for k, q in enumerate(chars.tolist()):
        if q in _CTRL:
            ctrl[k] = _CTRL[q]
            cnt = 0
            continue
        is_data[k] = True
        de, d = _DEC[q]
        byte[k] = d
        if cnt is None:
            continue
        want, nxt = _ENC[cnt][d]
        if want != q:
            if all(_ENC[c][d][0] != q for c in _ENC):
                raise DviError(f"channel {channel}, character {where(k)}: {q:#012b} is neither a control code nor "
                               f"a TMDS data character (invalid symbol)")
            raise DviError(f"channel {channel}, character {where(k)}: {q:#012b} carries byte {d:#04x} at the wrong "
                           f"DC balance: at running disparity {cnt:+d} an encoder sends {want:#012b}")
        cnt = nxt
    return is_data, byte, ctrl


def receive(bits, mode: str | VideoMode) -> DviCapture:
    """Decode and check the bit streams ``bits`` = (channel 0, channel 1, channel 2), numpy arrays of 0/1,
    one per bit time, each starting at any bit. Returns the whole frames and the timing found; raises
    :class:`DviError` at the first breach of the DVI rules or of ``mode``'s timing."""
    m = mode_of(mode)
    if len(bits) != 3:
        raise DviError(f"a DVI link has three data channels, got {len(bits)} bit streams")
    offsets = tuple(align(b, c) for c, b in enumerate(bits))
    chars = [characters(b, o) for b, o in zip(bits, offsets, strict=True)]
    # deskew: the first control -> data edge of each channel
    firsts = []
    for c, ch in enumerate(chars):
        is_ctrl = np.isin(ch, CONTROL)
        rise = np.nonzero(is_ctrl[:-1] & ~is_ctrl[1:])[0]
        if len(rise) == 0:
            raise DviError(f"channel {c}: no data period (DE never rises) in {len(ch)} characters")
        firsts.append(int(rise[0]) + 1)
    skew = tuple(f - min(firsts) for f in firsts)
    if max(skew) > m.h_total // 2:
        raise DviError(f"channels skewed by {skew} characters: more than half a line ({m.h_total // 2}) apart")
    n = min(len(ch) - s for ch, s in zip(chars, skew, strict=True))
    chars = [ch[s:s + n] for ch, s in zip(chars, skew, strict=True)]

    def where(c):
        return lambda k: f"{k} (bit {offsets[c] + 10 * (k + skew[c])})"

    dec = [_check_characters(ch, c, where(c)) for c, ch in enumerate(chars)]
    de = dec[0][0]
    for c in (1, 2):
        bad = np.nonzero(dec[c][0] != de)[0]
        if len(bad):
            k = int(bad[0])
            raise DviError(f"channel {c}, character {where(c)(k)}: {'data' if dec[c][0][k] else 'control'} period "
                           f"while channel 0 is in a {'data' if de[k] else 'control'} period (DE differs)")
        bad = np.nonzero((~de) & (dec[c][2] != 0))[0]
        if len(bad):
            k = int(bad[0])
            raise DviError(f"channel {c}, character {where(c)(k)}: control code CTL{2 * c - 1}:CTL{2 * c - 2} = "
                           f"{dec[c][2][k]:02b}, DVI 1.0 reserves them (0)")
    return _timing(m, de, dec, n, offsets, skew, where(0))


def _timing(m: VideoMode, de, dec, n, offsets, skew, where) -> DviCapture:
    ctrl = dec[0][2]
    known = int(np.nonzero(ctrl >= 0)[0][0])  # the first control character: syncs known from here
    # the sync levels, held through data periods (a receiver keeps the last control period's)
    idx = np.where(ctrl >= 0, np.arange(n), 0)
    idx = np.maximum.accumulate(idx)
    hs = (ctrl[idx] & 1) == int(m.h_pol)
    vs = (ctrl[idx] >> 1 & 1) == int(m.v_pol)
    hs[:known] = vs[:known] = False

    def whole(runs):  # runs that begin after the syncs are known and end before the stream does
        return [(s, e) for s, e in runs if s > known and e < n]

    de_runs, hs_runs, vs_runs = whole(_runs(de)), whole(_runs(hs)), whole(_runs(vs))
    name = m.name
    found = {}
    for s, e in de_runs:
        if e - s != m.h_active:
            raise DviError(f"DE run of {e - s} characters at character {where(s)}: mode {name} has {m.h_active} "
                           f"active pixels per line")
    for s, e in hs_runs:
        if e - s != m.h_sync:
            raise DviError(f"horizontal sync pulse {e - s} characters wide at character {where(s)}: mode {name} "
                           f"says {m.h_sync}")
    hs_starts = np.array([s for s, _ in _runs(hs) if s > known], dtype=np.int64)
    for a, b in zip(hs_starts[:-1], hs_starts[1:], strict=True):
        if b - a != m.h_total:
            raise DviError(f"horizontal syncs {b - a} characters apart at character {where(int(b))}: mode {name} "
                           f"has {m.h_total} per line")
    for s, e in de_runs:
        before = hs_starts[hs_starts < s]
        after = hs_starts[hs_starts >= e]
        if len(before) and s - before[-1] != m.h_start:
            raise DviError(f"DE begins {s - before[-1]} characters after the horizontal sync's leading edge at "
                           f"character {where(s)}: mode {name} says {m.h_start} (sync {m.h_sync} + back porch "
                           f"{m.h_back})")
        if len(after) and after[0] - e != m.h_front:
            raise DviError(f"horizontal front porch of {after[0] - e} characters after character {where(e)}: mode "
                           f"{name} says {m.h_front}")
    line = m.h_total
    for s, e in vs_runs:
        if e - s != m.v_sync * line:
            raise DviError(f"vertical sync of {(e - s) / line:g} lines ({e - s} characters) at character "
                           f"{where(s)}: mode {name} says {m.v_sync}")
    vs_starts = [s for s, _ in _runs(vs) if s > known]
    for s in vs_starts:
        if s not in set(hs_starts.tolist()):
            raise DviError(f"vertical sync begins at character {where(s)}, not with a horizontal sync's leading "
                           f"edge (mode {name})")
    frames = []
    de_all = [(s, e) for s, e in _runs(de) if s > known]
    for i, v0 in enumerate(vs_starts):
        v1 = vs_starts[i + 1] if i + 1 < len(vs_starts) else None
        lines = [(s, e) for s, e in de_all if s > v0 and (v1 is None or s < v1)]
        if v1 is None and (len(lines) < m.v_active or lines[-1][1] >= n):
            break  # the stream ends inside this frame
        if len(lines) != m.v_active:
            raise DviError(f"frame after the vertical sync at character {where(v0)} has {len(lines)} active lines: "
                           f"mode {name} says {m.v_active}")
        first = lines[0][0] - v0
        if first != m.v_start * line + m.h_start:
            raise DviError(f"first active line begins {first} characters after the vertical sync at character "
                           f"{where(v0)}: mode {name} says {m.v_start * line + m.h_start} (sync {m.v_sync} + back "
                           f"porch {m.v_back} lines, then {m.h_start})")
        if v1 is not None and v1 - lines[-1][1] != m.v_front * line + m.h_front:
            raise DviError(f"vertical front porch of {(v1 - lines[-1][1] - m.h_front) / line:g} lines before the "
                           f"vertical sync at character {where(v1)}: mode {name} says {m.v_front}")
        rows = [np.stack([dec[c][1][s:e] for c in (2, 1, 0)], axis=1) for s, e in lines]
        frames.append(np.stack(rows).astype(np.uint8))
    if de_runs:
        found.update(h_active=de_runs[0][1] - de_runs[0][0])
    if hs_runs:
        found.update(h_sync=hs_runs[0][1] - hs_runs[0][0])
    if len(hs_starts) > 1:
        found.update(h_total=int(hs_starts[1] - hs_starts[0]))
    if vs_runs:
        found.update(v_sync=(vs_runs[0][1] - vs_runs[0][0]) // line)
    if frames:
        found.update(v_active=frames[0].shape[0])
    found.update(hsync_pulses=len(hs_runs), vsync_pulses=len(vs_runs), de_runs=len(de_runs))
    return DviCapture(frames, offsets, skew, found, n)
