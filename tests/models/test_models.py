"""Bit-true models (eyestereo.tools.*) against independent references.

References are OpenCV (cv2.Sobel, cv2.filter2D in float64, exact for these integer sums), plain Python
loops and hand-computed constants; nothing expected is produced by the code under test.
"""

from __future__ import annotations

import math
from pathlib import Path

import cv2
import numpy as np
import pytest

from eyestereo.hdl.common import csd
from eyestereo.tools.models import convolve as conv
from eyestereo.tools.models import sobel as sob
from eyestereo.tools.models.line_delay import line_delay
from eyestereo.tools.models.border import correlate_int, interior_mask

DATA = Path(__file__).resolve().parents[1] / "data"
REAL_IMAGES = ["tsukuba_im3.png", "chessboard_left01.jpg"]


def grey(name: str) -> np.ndarray:
    img = cv2.imread(str(DATA / name), cv2.IMREAD_GRAYSCALE)
    assert img is not None, f"cannot read {name}"
    return img


def random_u8(h: int, w: int, seed: int) -> np.ndarray:
    return np.random.default_rng(seed).integers(0, 256, size=(h, w), dtype=np.uint8)


def loop_interior(h: int, w: int, r: int) -> np.ndarray:
    m = np.zeros((h, w), dtype=bool)
    for y in range(h):
        for x in range(w):
            m[y, x] = r <= y < h - r and r <= x < w - r
    return m


def checkerboard(h: int, w: int, top: int, phase: int) -> np.ndarray:
    return np.array([[top if (x + y + phase) % 2 else 0 for x in range(w)] for y in range(h)], dtype=np.int64)


# --------------------------------------------------------------------------------------------------
# Sobel


def assert_sobel_matches_opencv(img: np.ndarray) -> None:
    h, w = img.shape
    ix, iy, mask = sob.sobel(img)
    np.testing.assert_array_equal(mask, loop_interior(h, w, 1))
    dx = cv2.Sobel(img, cv2.CV_64F, 1, 0, ksize=3)
    dy = cv2.Sobel(img, cv2.CV_64F, 0, 1, ksize=3)
    ref_x = np.floor(dx / 8).astype(np.int64)
    ref_y = np.floor(dy / 8).astype(np.int64)
    np.testing.assert_array_equal(ix[mask], ref_x[mask])
    np.testing.assert_array_equal(iy[mask], ref_y[mask])
    assert ix[mask].min() >= -128 and ix[mask].max() <= 127
    assert iy[mask].min() >= -128 and iy[mask].max() <= 127


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
@pytest.mark.parametrize("h,w", [(3, 3), (3, 8), (8, 3), (17, 23), (64, 48)])
def test_sobel_matches_opencv_on_random_images(h, w, seed):
    assert_sobel_matches_opencv(random_u8(h, w, seed))


@pytest.mark.parametrize("name", REAL_IMAGES)
def test_sobel_matches_opencv_on_real_images(name):
    img = grey(name)
    assert_sobel_matches_opencv(img)
    ix, iy, mask = sob.sobel(img)
    assert np.count_nonzero(ix[mask]) > 0 and np.count_nonzero(iy[mask]) > 0  # not a trivial image


def test_sobel_sign_convention_on_ramps():
    h, w = 6, 7
    right = np.array([[10 * x for x in range(w)] for _ in range(h)], dtype=np.uint8)  # brighter to the right
    down = right.T.copy()  # brighter downward
    ix, iy, mask = sob.sobel(right)
    # Gx = (1 + 2 + 1) * (10 * (x + 1) - 10 * (x - 1)) = 80 -> 80 / 8 = 10; Gy = 0
    assert (ix[mask] == 10).all()
    assert (iy[mask] == 0).all()
    ix, iy, mask = sob.sobel(down)
    assert (iy[mask] == 10).all()
    assert (ix[mask] == 0).all()


def test_sobel_code_range_is_attained_on_steps():
    step = np.zeros((5, 6), dtype=np.uint8)
    step[:, 3:] = 255  # dark -> bright, left to right
    ix, _, _ = sob.sobel(step)
    assert ix[2, 2] == 127 and ix[2, 3] == 127  # floor(1020 / 8)
    ix, _, _ = sob.sobel(255 - step)
    assert ix[2, 2] == -128 and ix[2, 3] == -128  # floor(-1020 / 8)
    _, iy, _ = sob.sobel(step.T.copy())
    assert iy[2, 2] == 127
    _, iy, _ = sob.sobel(255 - step.T)
    assert iy[2, 2] == -128


def test_sobel_rounds_towards_minus_infinity():
    # Right-hand column at 1: Gx = 1 + 2 + 1 = 4 -> floor(4 / 8) = 0; mirrored, Gx = -4 -> floor(-0.5) = -1.
    img = np.zeros((3, 3), dtype=np.uint8)
    img[:, 2] = 1
    ix, _, _ = sob.sobel(img)
    assert ix[1, 1] == 0
    ix, _, _ = sob.sobel(img[:, ::-1].copy())
    assert ix[1, 1] == -1


def test_sobel_rejects_non_2d():
    with pytest.raises(ValueError):
        sob.sobel(np.zeros((3, 3, 3), dtype=np.uint8))


@pytest.mark.parametrize(
    "ix,iy,word",
    [
        (0, 0, 0),
        (1, 0, 0b000000000_000000001),
        (0, 1, 0b000000001_000000000),
        (-1, 0, 0b000000000_111111111),
        (0, -1, 0b111111111_000000000),
        (127, -128, 0b110000000_001111111),
        (-128, 127, 0b001111111_110000000),
        (-1, -1, 0x3FFFF),
        (5, -3, (0b111111101 << 9) | 0b000000101),
        (-256, 255, (0b011111111 << 9) | 0b100000000),
    ],
)
def test_sobel_pack_bit_layout(ix, iy, word):
    assert int(sob.pack(np.array(ix), np.array(iy))) == word
    uix, uiy = sob.unpack(np.array(word))
    assert (int(uix), int(uiy)) == (ix, iy)


def test_sobel_pack_unpack_round_trip_all_9_bit_pairs():
    v = np.arange(-256, 256, dtype=np.int64)
    ix, iy = np.meshgrid(v, v)
    words = sob.pack(ix, iy)
    assert words.min() >= 0 and words.max() < 1 << 18
    assert len(np.unique(words)) == 512 * 512  # injective
    uix, uiy = sob.unpack(words)
    np.testing.assert_array_equal(uix, ix)
    np.testing.assert_array_equal(uiy, iy)


def test_sobel_pack_of_model_output_unpacks_to_the_same_codes():
    ix, iy, _ = sob.sobel(random_u8(9, 11, 5))
    uix, uiy = sob.unpack(sob.pack(ix, iy))
    np.testing.assert_array_equal(uix, ix)
    np.testing.assert_array_equal(uiy, iy)


# --------------------------------------------------------------------------------------------------
# Convolve


def filter2d_floor(img: np.ndarray, kernel: np.ndarray, shift: int) -> np.ndarray:
    """Correlation by OpenCV in float64 (exact for these integer sums), floored by 2**shift."""
    ref = cv2.filter2D(img.astype(np.float64), cv2.CV_64F, kernel.astype(np.float64), anchor=(-1, -1),
                       borderType=cv2.BORDER_REFLECT_101)
    return np.floor(ref / (1 << shift)).astype(np.int64)


def random_kernel(n: int, seed: int, lo: int = -9, hi: int = 10) -> np.ndarray:
    rng = np.random.default_rng(seed)
    k = rng.integers(lo, hi, size=(n, n))
    k[0, 0] = -abs(k[0, 0]) - 1  # always at least one negative coefficient
    k[-1, 1] = abs(k[-1, 1]) + 1  # ... and one positive one
    return k


def random_separable(n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    col = rng.integers(-4, 5, size=n)
    row = rng.integers(-4, 5, size=n)
    col[0], row[-1] = -3, 2
    return np.outer(col, row)


CONV_CASES = (
    [(f"rand{n}x{n}s{s}", random_kernel(n, s), s % 6) for n in (3, 5) for s in range(4)]
    + [(f"sep{n}x{n}s{s}", random_separable(n, 10 + s), s) for n in (3, 5) for s in range(3)]
    + [
        ("binomial3/16", np.outer([1, 2, 1], [1, 2, 1]), 4),
        ("binomial5/256", np.outer([1, 4, 6, 4, 1], [1, 4, 6, 4, 1]), 8),
        ("sobel_x", sob.KX, 0),
        ("laplace", np.array([[0, 1, 0], [1, -4, 1], [0, 1, 0]]), 0),
        ("asymmetric", np.array([[1, 2, 3], [4, 5, 6], [7, 8, -9]]), 2),  # catches a kernel flip
    ]
)


@pytest.mark.parametrize("name,kernel,shift", CONV_CASES, ids=[c[0] for c in CONV_CASES])
def test_convolve_matches_filter2d_on_interior(name, kernel, shift):
    n = kernel.shape[0]
    r = n // 2
    for seed, (h, w) in enumerate([(n, n), (n + 1, 2 * n + 3), (24, 31)]):
        img = random_u8(h, w, seed)
        out, mask = conv.convolve(img, kernel, shift)
        np.testing.assert_array_equal(mask, loop_interior(h, w, r))
        ref = filter2d_floor(img, kernel, shift)
        np.testing.assert_array_equal(out[mask], ref[mask])


def test_convolve_matches_filter2d_on_real_image():
    img = grey("tsukuba_im3.png")
    kernel = random_kernel(5, 99)
    out, mask = conv.convolve(img, kernel, 3)
    np.testing.assert_array_equal(out[mask], filter2d_floor(img, kernel, 3)[mask])


def test_convolve_is_correlation_not_convolution():
    img = np.zeros((3, 3), dtype=np.uint8)
    img[1, 2] = 1  # pixel right of centre
    kernel = np.array([[0, 0, 0], [0, 0, 7], [0, 0, 0]])  # weight on the right-hand neighbour
    out, _ = conv.convolve(img, kernel, 0)
    assert out[1, 1] == 7


def test_check_kernel_separable_is_outer_product():
    col, row = [1, -2, 3], [4, 0, -1]
    k, separable = conv.check_kernel(col=col, row=row)
    assert separable
    assert k.tolist() == [[4, 0, -1], [-8, 0, 2], [12, 0, -3]]
    k, separable = conv.check_kernel(kernel=[[1, 2, 3], [4, 5, 6], [7, 8, 9]])
    assert not separable
    assert k.dtype == np.int64


def minimal_width(lo: int, hi: int) -> tuple[int, bool]:
    """Smallest word holding [lo, hi]: two's complement if lo < 0, else unsigned (at least 1 bit)."""
    signed = lo < 0
    b = 1
    while True:
        if signed and -(2 ** (b - 1)) <= lo and hi <= 2 ** (b - 1) - 1:
            return b, True
        if not signed and hi <= 2**b - 1:
            return b, False
        b += 1


def exact_range(kernel: np.ndarray, data_width: int, shift: int) -> tuple[int, int]:
    top = 2**data_width - 1
    neg = sum(int(c) for c in kernel.flat if c < 0) * top
    pos = sum(int(c) for c in kernel.flat if c > 0) * top
    return math.floor(neg / 2**shift), math.floor(pos / 2**shift)  # exact: ints, true division of ints


@pytest.mark.parametrize(
    "kernel,dw,shift,want",
    [
        (np.outer([1, 2, 1], [1, 2, 1]), 8, 4, (8, False)),  # sum <= 4080, / 16 -> 255
        (np.outer([1, 2, 1], [1, 2, 1]), 8, 0, (12, False)),  # 4080
        (sob.KX, 8, 0, (11, True)),  # -1020 .. 1020
        (sob.KX, 8, 3, (8, True)),  # -128 .. 127
        (-np.outer([1, 2, 1], [1, 2, 1]), 8, 4, (9, True)),  # -255 .. 0
        (np.zeros((3, 3), dtype=np.int64), 8, 0, (1, False)),
        (np.ones((5, 5), dtype=np.int64), 1, 0, (5, False)),  # 0 .. 25
        (np.array([[0, 0, 0], [0, -1, 0], [0, 0, 0]]), 8, 0, (9, True)),  # -255 .. 0
    ],
)
def test_output_width_hand_computed(kernel, dw, shift, want):
    assert conv.output_width(kernel, dw, shift) == want


RANGE_CASES = CONV_CASES + [
    ("neg_only", -np.outer([1, 2, 1], [1, 2, 1]), 2),
    ("pos_only5", np.ones((5, 5), dtype=np.int64), 3),
    ("zero", np.zeros((3, 3), dtype=np.int64), 0),
]


@pytest.mark.parametrize("dw", [1, 8, 12])
@pytest.mark.parametrize("name,kernel,shift", RANGE_CASES, ids=[c[0] for c in RANGE_CASES])
def test_output_width_holds_every_output_and_is_tight(name, kernel, shift, dw):
    top = 2**dw - 1
    n = kernel.shape[0]
    lo, hi = exact_range(kernel, dw, shift)
    assert conv.output_range(kernel, dw, shift) == (lo, hi)
    bits, signed = conv.output_width(kernel, dw, shift)
    assert (bits, signed) == minimal_width(lo, hi)

    # The extremes are attained by the model: top where k > 0 (resp. k < 0), 0 elsewhere.
    hi_img = np.where(kernel > 0, top, 0)
    lo_img = np.where(kernel < 0, top, 0)
    assert conv.convolve(hi_img, kernel, shift)[0][n // 2, n // 2] == hi
    assert conv.convolve(lo_img, kernel, shift)[0][n // 2, n // 2] == lo

    images = [np.zeros((9, 10)), np.full((9, 10), top), checkerboard(9, 10, top, 0), checkerboard(9, 10, top, 1),
              np.tile(hi_img, (2, 2)), np.tile(lo_img, (2, 2))]
    images += [np.random.default_rng(s).integers(0, top + 1, size=(12, 13)) for s in range(3)]
    for img in images:
        out, mask = conv.convolve(img.astype(np.int64), kernel, shift)
        v = out[mask]
        if signed:
            assert v.min() >= -(2 ** (bits - 1)) and v.max() <= 2 ** (bits - 1) - 1
        else:
            assert v.min() >= 0 and v.max() <= 2**bits - 1
        assert lo <= v.min() and v.max() <= hi


@pytest.mark.parametrize("bits,signed", [(1, False), (8, False), (9, True), (11, True), (20, True), (3, True)])
def test_word_round_trip(bits, signed):
    if signed:
        values = np.arange(-(2 ** (bits - 1)), 2 ** (bits - 1))
    else:
        values = np.arange(0, 2**bits)
    if len(values) > 5000:
        values = np.concatenate([values[:2000], values[-2000:]])
    words = conv.to_word(values, bits)
    assert words.min() >= 0 and words.max() < 2**bits
    np.testing.assert_array_equal(conv.from_word(words, bits, signed), values)


def test_word_hand_computed():
    assert conv.to_word(np.array([-1, -256, 255, 0]), 9).tolist() == [511, 256, 255, 0]
    assert conv.from_word(np.array([511, 256, 255, 0]), 9, True).tolist() == [-1, -256, 255, 0]
    assert conv.from_word(np.array([511, 256]), 9, False).tolist() == [511, 256]
    assert conv.to_word(np.array([-5]), 4).tolist() == [0b1011]


def test_correlate_int_rejects_even_or_non_square_kernels():
    with pytest.raises(ValueError):
        correlate_int(np.zeros((5, 5)), np.ones((2, 2)))
    with pytest.raises(ValueError):
        correlate_int(np.zeros((5, 5)), np.ones((3, 5)))


def test_correlate_int_frame_smaller_than_kernel_is_all_zero():
    out = correlate_int(np.ones((2, 7), dtype=np.int64), np.ones((3, 3)))
    assert out.shape == (2, 7) and not out.any()


# --------------------------------------------------------------------------------------------------
# Line delay


@pytest.mark.parametrize("h,w", [(1, 1), (1, 5), (2, 1), (4, 3), (10, 17)])
def test_line_delay_model_is_the_line_above(h, w):
    frame = np.random.default_rng(h * w).integers(0, 1 << 36, size=(h, w), dtype=np.int64)
    out, mask = line_delay(frame)
    assert out.shape == frame.shape and mask.shape == frame.shape
    for y in range(1, h):
        for x in range(w):
            assert out[y, x] == frame[y - 1, x]
            assert mask[y, x]
    assert not mask[0].any()


# --------------------------------------------------------------------------------------------------
# interior_mask


@pytest.mark.parametrize(
    "h,w,r", [(3, 3, 1), (5, 5, 2), (4, 9, 1), (9, 4, 1), (10, 12, 2), (288, 352, 2), (1, 1, 0), (6, 7, 0)]
)
def test_interior_mask_shape_count_and_position(h, w, r):
    m = interior_mask(h, w, r)
    assert m.shape == (h, w) and m.dtype == bool
    assert m.sum() == (h - 2 * r) * (w - 2 * r)
    np.testing.assert_array_equal(m, loop_interior(h, w, r))


@pytest.mark.parametrize("h,w,r", [(2, 2, 1), (2, 10, 1), (10, 2, 1), (4, 4, 2), (3, 9, 2)])
def test_interior_mask_empty_when_window_never_fits(h, w, r):
    m = interior_mask(h, w, r)
    assert m.shape == (h, w)
    assert not m.any()


# --------------------------------------------------------------------------------------------------
# Canonical signed digits (hdl/window.py)


def test_csd_digits_sum_back_and_are_canonical():
    for k in range(-3000, 3000):
        digits = csd(k)
        assert sum(sign * 2**shift for sign, shift in digits) == k, k
        assert all(sign in (1, -1) for sign, _ in digits), k
        shifts = sorted(shift for _, shift in digits)
        assert all(s >= 0 for s in shifts), k
        assert len(set(shifts)) == len(shifts), k
        assert all(b - a >= 2 for a, b in zip(shifts, shifts[1:])), f"adjacent nonzero digits for {k}: {digits}"
        # A non-adjacent form never has more nonzero digits than plain binary.
        assert len(digits) <= bin(abs(k)).count("1"), k


@pytest.mark.parametrize(
    "k,want",
    [(0, set()), (1, {(1, 0)}), (-1, {(-1, 0)}), (3, {(-1, 0), (1, 2)}), (7, {(-1, 0), (1, 3)}),
     (6, {(-1, 1), (1, 3)}), (-6, {(1, 1), (-1, 3)}), (5, {(1, 0), (1, 2)})],
)
def test_csd_hand_computed(k, want):
    assert set(csd(k)) == want
