"""Bit-true model of :func:`eyestereo.hdl.video.pair_display.pair_display`: the board's monitor picture.

The block copies the newest rectified pair (two 8-bit images) and its feature lists from the frame store into
two block RAMs, marks every listed corner with a cross of :data:`MARK` pixels, and shows the RAMs in a video
mode. With the front end's matcher option (``matches``) it also draws each match of the frame's match list into a
1-bit plane: a horizontal segment on the left corner's row from the right corner's column (x - disparity) to the
left corner's (x), shown in the anaglyph (:data:`SEGMENT_RGB`), so the matches' lengths are their disparities. This
module declares what the block and its tests share: the mark, the cross, the segment, the register words the
block writes, the colour rule, and the expected picture from a pair, its features and its matches.
"""

from __future__ import annotations

import numpy as np

from eyestereo.tools.regmap import REGMAP

__all__ = ["CROSS", "MARK", "PIXEL_MAX", "SEGMENT_RGB", "SRAM_BASE", "check_geometry", "colour_rule", "copy_pair",
           "ctrl_words", "match_plane", "picture", "segment", "start_words"]

#: The mark code: a pixel of a corner's cross. Image pixels are clipped to PIXEL_MAX so no pixel looks like one.
MARK = 255
PIXEL_MAX = 254
#: A corner's cross, (dx, dy) in the order the block writes them: 9 pixels, arms of 2.
CROSS = ((0, 0), (-1, 0), (1, 0), (-2, 0), (2, 0), (0, -1), (0, 1), (0, -2), (0, 2))
#: Byte address of the register map's SRAM window (word w at SRAM_BASE + 4 w).
SRAM_BASE = REGMAP["SRAM"].offset

#: The colour of a match's segment in the anaglyph (cyan: neither the anaglyph's grey nor a mark's yellow).
SEGMENT_RGB = (0, 255, 255)

#: Zones of the picture (the block's zone code; 0 is black).
LEFT, RIGHT, ANAGLYPH = 1, 2, 3


def ctrl_words() -> tuple[int, int, int]:
    """(CTRL word that wants a rectified pair and its lists, CMD word that gives both back, the byte strobe both
    are written with). The strobe covers the byte of the four fields alone, so the host's mode and continuous
    bits (CTRL's byte 0) are never touched."""
    bits = [REGMAP.field(n)[1].lsb for n in ("CTRL.rect_want", "CTRL.feat_want", "CMD.rect_release",
                                             "CMD.feat_release")]
    if len({b // 8 for b in bits}) != 1:
        raise ValueError("the want and release fields must share one byte for a write that leaves the rest alone")
    want = (1 << bits[0]) | (1 << bits[1])
    release = (1 << bits[2]) | (1 << bits[3])
    return want, release, 1 << (bits[0] // 8)


def start_words() -> tuple[int, int]:
    """(CTRL byte 0 for the overlapped, continuous mode; CMD's start) that a board without a host writes at
    reset (the display's ``autostart``), each with byte strobe 1."""
    f_mode, f_cont, f_start = (REGMAP.field(n)[1] for n in ("CTRL.mode", "CTRL.continuous", "CMD.start"))
    if max(f_mode.lsb, f_cont.lsb, f_start.lsb) >= 8:
        raise ValueError("mode, continuous and start must lie in byte 0")
    overlapped = {name: code for code, name in f_mode.values}["overlapped"]
    return (overlapped << f_mode.lsb) | (1 << f_cont.lsb), 1 << f_start.lsb


def check_geometry(width: int, height: int, mode) -> None:
    """A pair of ``width x height`` images side by side (and the anaglyph below) must fit the mode."""
    for name, v in (("width", width), ("height", height)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < 8:
            raise ValueError(f"{name} must be an int >= 8, got {v!r}")
    if 2 * width > mode.h_active or 2 * height > mode.v_active:
        raise ValueError(f"a {width}x{height} pair side by side and its anaglyph below need {2 * width}x{2 * height} "
                         f"pixels, the mode shows {mode.h_active}x{mode.v_active}")


def copy_pair(left: np.ndarray, right: np.ndarray, features, *, max_features: int = 1023) -> tuple[np.ndarray,
                                                                                                   np.ndarray]:
    """The two RAMs after a copy: the images clipped to PIXEL_MAX, then the crosses of the first
    ``max_features`` features ``(x, y, cam)`` (cam 0 left, 1 right) written as MARK where inside the image."""
    ram_l = np.minimum(np.asarray(left, dtype=np.uint8), PIXEL_MAX).astype(np.uint8)
    ram_r = np.minimum(np.asarray(right, dtype=np.uint8), PIXEL_MAX).astype(np.uint8)
    if ram_l.shape != ram_r.shape or ram_l.ndim != 2:
        raise ValueError(f"left and right must be 2-D images of one size, got {ram_l.shape} and {ram_r.shape}")
    h, w = ram_l.shape
    for x, y, cam in list(features)[:max_features]:
        ram = ram_r if cam else ram_l
        for dx, dy in CROSS:
            if 0 <= x + dx < w and 0 <= y + dy < h:
                ram[y + dy, x + dx] = MARK
    return ram_l, ram_r


def segment(x: int, y: int, disparity: int, width: int, height: int) -> list[tuple[int, int]]:
    """The pixels ``(x, y)`` of a match's segment: row ``y``, columns ``x - disparity`` .. ``x`` (the right corner's
    column to the left corner's), in the order the block draws them, those inside the image."""
    if not 0 <= y < height:
        return []
    return [(c, y) for c in range(x - disparity, x + 1) if 0 <= c < width]


def match_plane(matches, width: int, height: int, *, max_matches: int = 1023) -> np.ndarray:
    """The block's match RAM after a copy (``height x width``, bool): the segments of the first ``max_matches``
    matches, each ``(x, y, disparity)`` (a match list's first three columns,
    :func:`eyestereo.tools.models.match_engine.parse_list`'s ``matches``)."""
    plane = np.zeros((height, width), dtype=bool)
    for m in list(matches)[:max_matches]:
        for c, r in segment(int(m[0]), int(m[1]), int(m[2]), width, height):
            plane[r, c] = True
    return plane


def colour_rule(zone: int, pl: int, pr: int, pm: bool = False) -> tuple[int, int, int]:
    """(red, green, blue) of a pixel of ``zone`` whose RAM codes are ``pl`` (left) and ``pr`` (right) and whose
    match bit is ``pm`` (a corner's mark wins over a segment)."""
    if zone == LEFT:
        return (255, 0, 0) if pl == MARK else (pl, pl, pl)
    if zone == RIGHT:
        return (0, 255, 0) if pr == MARK else (pr, pr, pr)
    if zone == ANAGLYPH:
        if MARK in (pl, pr):
            return (255, 255, 0)
        return SEGMENT_RGB if pm else (pl, pr, pr)
    return (0, 0, 0)


def picture(ram_l: np.ndarray, ram_r: np.ndarray, mode, ram_m: np.ndarray | None = None) -> np.ndarray:
    """The active picture (``mode.v_active x mode.h_active x 3``, uint8) the block shows from its RAMs: the left
    image at the top left, the right one beside it, their anaglyph below the left one (with ``ram_m``, the match
    plane, its segments), black elsewhere."""
    h, w = ram_l.shape
    check_geometry(w, h, mode)
    out = np.zeros((mode.v_active, mode.h_active, 3), dtype=np.uint8)
    grey = lambda a: np.repeat(a[:, :, None], 3, axis=2)  # noqa: E731
    top_l, top_r = grey(ram_l), grey(ram_r)
    top_l[ram_l == MARK] = (255, 0, 0)
    top_r[ram_r == MARK] = (0, 255, 0)
    ana = np.stack([ram_l, ram_r, ram_r], axis=2)
    if ram_m is not None:
        if ram_m.shape != ram_l.shape:
            raise ValueError(f"the match plane is {ram_m.shape}, the images {ram_l.shape}")
        ana[np.asarray(ram_m, dtype=bool)] = SEGMENT_RGB
    ana[(ram_l == MARK) | (ram_r == MARK)] = (255, 255, 0)
    out[:h, :w] = top_l
    out[:h, w:2 * w] = top_r
    out[h:2 * h, :w] = ana
    return out
