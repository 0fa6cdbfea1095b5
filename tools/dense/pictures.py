"""Pictures of dense disparity maps: one labelled row of panels per pair, colour-coded on one scale.

A row is the left image, then any number of disparity maps (ground truth and methods), each under its
label, with a strip below naming the pair and showing the colour scale. Every map of a row is coded on
the same scale, 0 .. ``vmax`` px (OpenCV's turbo map: dark blue far, dark red near; values above ``vmax``
take the top colour), so that the same colour means the same disparity in every panel; a pixel without a
value (unknown ground truth, no estimate) is black, which the turbo map never uses.

The row is an indexed picture on one fixed palette of 256 entries, :data:`PALETTE`: :data:`LEVELS` greys
(the left image, the paper, the text, black) and :data:`LEVELS` turbo colours (the maps). An 8-bit indexed
PNG of it (:func:`encode_png`) is about a third of the size of a colour one, and the same maps always give
the same bytes. The accuracy module (:func:`eyestereo.tools.dense.accuracy.write_pictures`) computes the
maps and writes the files.
"""

from __future__ import annotations

import struct
import zlib

import cv2
import numpy as np

__all__ = ["LEVELS", "PALETTE", "LABEL_HEIGHT", "GAP", "STRIP_HEIGHT", "map_indices", "picture_row",
           "encode_png"]

#: Grey levels and colour levels of the palette (128 + 128 = one byte per pixel).
LEVELS = 128
_RAMP = np.rint(np.arange(LEVELS) * 255.0 / (LEVELS - 1)).astype(np.uint8)
#: RGB palette: entries 0 .. 127 the greys from black to white, 128 .. 255 the turbo colours from 0 to vmax.
PALETTE = np.concatenate([np.repeat(_RAMP[:, None], 3, axis=1),
                          cv2.applyColorMap(_RAMP[None, :], cv2.COLORMAP_TURBO)[0, :, ::-1]]).astype(np.uint8)
#: Height of the label above each panel, gap between panels and around the row, height of the bottom strip (px).
LABEL_HEIGHT, GAP, STRIP_HEIGHT = 22, 6, 30
_FONT, _SCALE = cv2.FONT_HERSHEY_SIMPLEX, 0.5
_BLACK, _WHITE = 0, LEVELS - 1


def _grey_indices(grey: np.ndarray) -> np.ndarray:
    return np.rint(grey.astype(np.float64) * (LEVELS - 1) / 255.0).astype(np.uint8)


def map_indices(disparity, vmax: float) -> np.ndarray:
    """Palette indices of a float map (px, NaN = none): the turbo colours over 0 .. ``vmax``, black for NaN."""
    d = np.asarray(disparity, np.float64)
    if d.ndim != 2:
        raise ValueError(f"disparity map must be 2-D, got shape {d.shape}")
    if not vmax > 0:
        raise ValueError(f"the colour scale's top must be above 0 px, got {vmax}")
    valid = np.isfinite(d)
    level = np.rint(np.clip(np.where(valid, d, 0.0) / vmax, 0.0, 1.0) * (LEVELS - 1)).astype(np.uint8)
    return np.where(valid, LEVELS + level, _BLACK).astype(np.uint8)


def picture_row(image, maps: dict[str, np.ndarray], vmax: float, title: str,
                image_label: str = "left image") -> np.ndarray:
    """The row as palette indices (uint8, :data:`PALETTE`): ``image`` (grey uint8) and each of ``maps``
    (label -> float map, the image's size), labelled, and below them ``title`` and the scale 0 .. ``vmax`` px."""
    img = np.asarray(image)
    if img.ndim != 2 or img.dtype != np.uint8:
        raise ValueError(f"the image must be grey uint8, got {img.dtype} of shape {img.shape}")
    h, w = img.shape
    bad = [k for k, v in maps.items() if np.shape(v) != (h, w)]
    if bad:
        raise ValueError(f"maps {', '.join(bad)} are not {w}x{h} like the image")
    labels = [image_label, *maps]
    width = GAP + len(labels) * (w + GAP)
    y0 = LABEL_HEIGHT + h + GAP  # top of the bottom strip
    # paper, text and the left image as grey first (the text's anti-aliased edges are greys too) ...
    grey = np.full((y0 + STRIP_HEIGHT, width), 255, np.uint8)

    def text(s: str, x: int, y: int) -> None:
        cv2.putText(grey, s, (x, y), _FONT, _SCALE, 0, 1, cv2.LINE_AA)

    for i, label in enumerate(labels):
        text(label, GAP + i * (w + GAP), LABEL_HEIGHT - 7)
    grey[LABEL_HEIGHT:LABEL_HEIGHT + h, GAP:GAP + w] = img
    text(title, GAP, y0 + 18)
    right = f"{vmax:g} px   black: unknown / no estimate"
    (tw, _), _ = cv2.getTextSize(right, _FONT, _SCALE, 1)
    (lw, _), _ = cv2.getTextSize(title, _FONT, _SCALE, 1)
    # the bar: 4 columns per colour, narrower where the row is (small images); what does not fit is cut
    bar_w = int(np.clip(width - 3 * GAP - lw - 52 - tw - 8, 0, 4 * LEVELS))
    xb = width - GAP - tw - 8 - bar_w
    text("0 px", xb - 44, y0 + 18)
    text(right, xb + bar_w + 8, y0 + 18)
    out = _grey_indices(grey)
    # ... then the maps and the scale bar in palette colours
    for i, m in enumerate(maps.values(), start=1):
        x = GAP + i * (w + GAP)
        out[LABEL_HEIGHT:LABEL_HEIGHT + h, x:x + w] = map_indices(m, vmax)
    if bar_w:
        levels = (np.arange(bar_w) * LEVELS // bar_w).astype(np.uint8)
        out[y0 + 8:y0 + 20, xb:xb + bar_w] = LEVELS + levels[None, :]
    return out


def _chunk(kind: bytes, data: bytes) -> bytes:
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))


def encode_png(indices) -> bytes:
    """An 8-bit indexed PNG of palette indices with :data:`PALETTE` (filter type 0 on every row, the PNG
    book's advice for palette pictures; zlib level 9)."""
    idx = np.ascontiguousarray(indices, np.uint8)
    if idx.ndim != 2:
        raise ValueError(f"indices must be 2-D, got shape {idx.shape}")
    h, w = idx.shape
    rows = np.concatenate([np.zeros((h, 1), np.uint8), idx], axis=1)  # a 0 filter byte before each row
    return (b"\x89PNG\r\n\x1a\n" + _chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 3, 0, 0, 0))
            + _chunk(b"PLTE", PALETTE.tobytes()) + _chunk(b"IDAT", zlib.compress(rows.tobytes(), 9))
            + _chunk(b"IEND", b""))
