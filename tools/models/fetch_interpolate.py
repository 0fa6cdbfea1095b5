"""Bit-true model of :func:`eyestereo.hdl.rectify.fetch_interpolate.fetch_interpolate` (thesis 4.3, Figs. 4.9-4.11).

For every coordinate pair (Pl, Pr) of the warper (:mod:`eyestereo.tools.models.coordinate_warper`) the
block outputs two 8-bit pixels of the stereo stream: the left camera image interpolated at Pl (``cam`` 0),
then the right one at Pr (``cam`` 1).

**Interpolation.** A coordinate is ufix[n, F] (F = ``frac``): ``x0 = x >> F``, ``dx = x & (2**F - 1)``,
likewise y; S = 2**F. The four weights, in the order the pixels come (fetch-port index 0..3, pixels
(x0+1, y0+1), (x0, y0+1), (x0+1, y0), (x0, y0)), are the products

    w0 = dx * dy,  w1 = (S - dx) * dy,  w2 = dx * (S - dy),  w3 = (S - dx) * (S - dy)

(exact integers, sum S**2), accumulated as ``acc = sum(w_i * p_i)`` and rounded half up:
``out = (acc + S**2 / 2) >> 2F`` (``out = acc`` for F = 0). This is the bilinear interpolation of the
pixels at (x0 + dx / S, y0 + dy / S) rounded to the nearest grey level (ties up): no error beyond the
final rounding (at most 0.5 grey levels) on top of the coordinate's own quantisation. A side flagged out
of range gives 0 (black) and no memory request.

**Fetches.** The block keeps, per camera, the 2x2 neighbourhood of that camera's previous in-range
pixel (its ``(x0, y0)`` and four pixels) and asks the memory only for the pixels of the new
neighbourhood that are not in it: with ``ddx = x0 - x0_prev`` and ``ddy = y0 - y0_prev``, pixel
``(x0 + ox, y0 + oy)`` is reused when ``ox + ddx`` and ``oy + ddy`` are both 0 or 1. The mask of the
request (fetch-port bit i = index i wanted) is the set of the others; a mask of 0 sends no request
(the same neighbourhood again). The kept neighbourhoods are emptied by ``rst`` and after a frame's last
pair (``eof``): the frame buffers hold a new frame then.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from eyestereo.tools.packed import PackedWord

__all__ = ["MAX_FRAC", "OFFSETS", "REUSE", "interpolate", "fetch_interpolate", "reads", "requests",
           "side_word", "stereo_stream", "weights"]

#: Largest ``frac`` the block accepts: weights of 2F+1 <= 17 bits keep both products in an 18x18
#: multiplier (the Spartan-3E's MULT18X18).
MAX_FRAC = 8
#: (ox, oy) of fetch-port index i (hdl/interfaces/fetch_port.py's order).
OFFSETS = ((1, 1), (0, 1), (1, 0), (0, 0))


def _index(ox: int, oy: int) -> int:
    return (1 - ox) + 2 * (1 - oy)


def _reuse_table() -> dict[tuple[int, int], tuple[int, tuple[int, ...]]]:
    """(ddx, ddy) -> (mask of the pixels to fetch, for each index the kept pixel's index or -1)."""
    out = {}
    for ddy in (-1, 0, 1):
        for ddx in (-1, 0, 1):
            mask, src = 0, []
            for i, (ox, oy) in enumerate(OFFSETS):
                jx, jy = ox + ddx, oy + ddy
                if jx in (0, 1) and jy in (0, 1):
                    src.append(_index(jx, jy))
                else:
                    src.append(-1)
                    mask |= 1 << i
            out[(ddx, ddy)] = (mask, tuple(src))
    return out


#: The reuse rule: (ddx, ddy) -> (request mask, source index in the kept neighbourhood per index).
REUSE = _reuse_table()


def side_word(frac: int) -> PackedWord:
    """The block's side descriptor, queued between its requester and its interpolator (one per side of a
    pair), least significant field first: the pair's ``eof``, ``eol``, the camera, out of range, the
    request ``mask``, ``src`` (per index 0..3 the kept pixel's index, 2 bits each, index 0 lowest) and
    the fractions ``dx``, ``dy`` (``max(frac, 1)`` bits: at least one bit, 0 for ``frac`` 0)."""
    if not 0 <= frac <= MAX_FRAC:
        raise ValueError(f"frac must be 0..{MAX_FRAC}, got {frac}")
    fw = max(frac, 1)
    return PackedWord("fetch side", [("eof", 1), ("eol", 1), ("cam", 1), ("oor", 1), ("mask", 4),
                                     ("src", 2 * len(OFFSETS)), ("dx", fw), ("dy", fw)])


def weights(dx: npt.ArrayLike, dy: npt.ArrayLike, frac: int) -> npt.NDArray[np.int64]:
    """The four weights (index order) of fractions ``dx``, ``dy``: shape ``(4,) + dx.shape``."""
    dx = np.asarray(dx, dtype=np.int64)
    dy = np.asarray(dy, dtype=np.int64)
    s = np.int64(1) << frac
    return np.stack([dx * dy, (s - dx) * dy, dx * (s - dy), (s - dx) * (s - dy)])


def interpolate(image: npt.ArrayLike, x: npt.ArrayLike, y: npt.ArrayLike, oor: npt.ArrayLike,
                frac: int) -> npt.NDArray[np.uint8]:
    """The block's output for coordinates ``x``, ``y`` (ufix codes, F = ``frac``) into ``image``.

    ``oor`` marks sides out of range (output 0; their coordinates are not used).
    """
    img = np.asarray(image)
    if img.ndim != 2 or img.dtype != np.uint8:
        raise ValueError(f"want a 2-D uint8 image, got {img.dtype} {img.shape}")
    if not 0 <= frac <= MAX_FRAC:
        raise ValueError(f"frac must be 0..{MAX_FRAC}, got {frac}")
    x = np.asarray(x, dtype=np.int64)
    y = np.asarray(y, dtype=np.int64)
    bad = np.asarray(oor).astype(bool)
    h, w = img.shape
    x0 = np.where(bad, 0, x >> frac)
    y0 = np.where(bad, 0, y >> frac)
    if (x0 > w - 2).any() or (y0 > h - 2).any():
        raise ValueError("an in-range coordinate points outside the image's [0, W-2] x [0, H-2]")
    m = (1 << frac) - 1
    wts = weights(x & m, y & m, frac)
    p = img.astype(np.int64)
    acc = np.zeros(x.shape, dtype=np.int64)
    for i, (ox, oy) in enumerate(OFFSETS):
        acc += wts[i] * p[y0 + oy, x0 + ox]
    out = (acc + ((1 << (2 * frac)) >> 1)) >> (2 * frac)
    out[bad] = 0
    return out.astype(np.uint8)


def fetch_interpolate(left: npt.ArrayLike, right: npt.ArrayLike, pairs: dict[str, npt.ArrayLike],
                      frac: int) -> tuple[npt.NDArray[np.uint8], npt.NDArray[np.uint8]]:
    """(left, right) outputs for the warper's ``pairs`` (fields ``xl, yl, xr, yr, oor_l, oor_r``, any shape)."""
    return (interpolate(left, pairs["xl"], pairs["yl"], pairs["oor_l"], frac),
            interpolate(right, pairs["xr"], pairs["yr"], pairs["oor_r"], frac))


def requests(pairs: dict[str, npt.ArrayLike], frac: int) -> dict[str, npt.NDArray[np.int64]]:
    """The fetch-port requests for a sequence of pairs (flat, in the warper's order, frames back to back).

    Returns flat arrays ``x, y, cam, mask`` in request order (left before right within a pair). The
    neighbourhoods kept are emptied after every pair with ``eof`` (and at the start).
    """
    f = {k: np.asarray(v, dtype=np.int64).ravel() for k, v in pairs.items()}
    n = len(f["xl"])
    eof = f.get("eof", np.zeros(n, dtype=np.int64))
    frame = np.concatenate([[0], np.cumsum(eof)[:-1]]) if n else np.zeros(0, dtype=np.int64)
    out = []
    for cam, (xk, yk, ok) in enumerate((("xl", "yl", "oor_l"), ("xr", "yr", "oor_r"))):
        keep = np.nonzero(f[ok] == 0)[0]
        x0 = f[xk][keep] >> frac
        y0 = f[yk][keep] >> frac
        fr = frame[keep]
        mask = np.full(len(keep), 15, dtype=np.int64)
        if len(keep) > 1:
            ddx = x0[1:] - x0[:-1]
            ddy = y0[1:] - y0[:-1]
            same = fr[1:] == fr[:-1]
            m = np.full(len(keep) - 1, 15, dtype=np.int64)
            for (a, b), (mk, _) in REUSE.items():
                m[same & (ddx == a) & (ddy == b)] = mk
            mask[1:] = m
        sent = mask != 0
        # order key: pair index * 2 + cam
        out.append((keep[sent] * 2 + cam, x0[sent], y0[sent], np.full(int(sent.sum()), cam), mask[sent]))
    key = np.concatenate([o[0] for o in out])
    order = np.argsort(key, kind="stable")
    return {name: np.concatenate([o[i] for o in out])[order].astype(np.int64)
            for i, name in ((1, "x"), (2, "y"), (3, "cam"), (4, "mask"))}


def reads(mask: npt.ArrayLike) -> int:
    """Pixels read from memory by requests with these masks (popcount)."""
    m = np.asarray(mask, dtype=np.int64)
    return int(sum(((m >> b) & 1).sum() for b in range(4)))


def stereo_stream(left: npt.ArrayLike, right: npt.ArrayLike) -> dict[str, npt.NDArray[np.int64]]:
    """The stereo stream of two output frames: flat ``data, cam, eol, eof`` (left (x, y), then right)."""
    lf, rt = np.asarray(left), np.asarray(right)
    if lf.shape != rt.shape or lf.ndim != 2:
        raise ValueError(f"left and right must be 2-D of one shape, got {lf.shape} and {rt.shape}")
    h, w = lf.shape
    data = np.stack([lf.ravel(), rt.ravel()], axis=1).ravel().astype(np.int64)
    cam = np.tile([0, 1], h * w)
    eol = np.zeros((h, w), dtype=np.int64)
    eol[:, -1] = 1
    eof = np.zeros((h, w), dtype=np.int64)
    eof[-1, -1] = 1
    return {"data": data, "cam": cam, "eol": np.repeat(eol.ravel(), 2), "eof": np.repeat(eof.ravel(), 2)}
