"""Match engine model (tools/models/match_engine.py): against a plain loop written from the rules, the
descriptor words against the census model and a hand-packed window, the order key, bad settings."""

from __future__ import annotations

import numpy as np
import pytest

from eyestereo.tools.models import census as C
from eyestereo.tools.models import match_engine as E


def loop_reference(fl, fr, a, b, *, cost, limit, d_min, d_max, rows, uniqueness, lr_check, max_matches):
    """The rules of the feature matcher's docstring, one pair at a time (no numpy tricks): the listed
    (left index, right index, dy, disparity, cost), total, candidates."""
    def pair_cost(i, j):
        if cost == "sad":
            return int(sum(abs(int(p) - int(q)) for p, q in zip(a[i], b[j])))
        return int(sum(bool(p) != bool(q) for p, q in zip(a[i], b[j])))

    def key(i, j):  # cost, |dy|, disparity, dy: smallest first
        dy = int(fr[j][1] - fl[i][1])
        return (pair_cost(i, j), abs(dy), int(fl[i][0] - fr[j][0]), dy)

    cands = {i: [j for j in range(len(fr)) if abs(int(fr[j][1] - fl[i][1])) <= rows
                 and d_min <= int(fl[i][0] - fr[j][0]) <= d_max] for i in range(len(fl))}
    of_right = {}
    for i, js in cands.items():
        for j in js:
            of_right.setdefault(j, []).append(i)
    found = []
    for i in range(len(fl)):
        js = sorted(cands[i], key=lambda j: key(i, j))
        if not js:
            continue
        best = key(i, js[0])[0]
        second = key(i, js[1])[0] if len(js) > 1 else None
        if best >= limit or (second is not None and best * (100 + uniqueness) > second * 100):
            continue
        j = js[0]
        if lr_check and min(of_right[j], key=lambda k: key(k, j)) != i:
            continue
        found.append((i, j, int(fr[j][1] - fl[i][1]), int(fl[i][0] - fr[j][0]), best))
    return found[:max_matches], len(found), sum(len(js) for js in cands.values())


def random_case(seed: int, cost: str, window: int, w: int = 60, h: int = 24, n: int = 40):
    """Random corners (raster order) of both cameras, on few rows so that rows share candidates, and
    descriptors with few levels so that costs tie often."""
    rng = np.random.default_rng(seed)

    def corners():
        keys = np.sort(rng.choice(w * h, n, replace=False))
        return np.stack([keys % w, keys // w], axis=1).astype(np.int64)

    fl, fr = corners(), corners()
    size = window * window - (cost == "census")
    if cost == "sad":
        a, b = rng.integers(0, 4, (n, size)) * 60, rng.integers(0, 4, (n, size)) * 60
    else:
        a, b = rng.integers(0, 2, (n, size)).astype(bool), rng.integers(0, 2, (n, size)).astype(bool)
    return fl, fr, a, b


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("cost,window,limit", [("sad", 5, 2200), ("census", 5, 13), ("census", 7, 26)])
@pytest.mark.parametrize("rows,uniqueness,lr_check", [(0, 0, False), (1, 0, True), (2, 10, True), (1, 30, False)])
def test_equals_the_rules_one_pair_at_a_time(seed, cost, window, limit, rows, uniqueness, lr_check):
    fl, fr, a, b = random_case(seed, cost, window)
    kw = dict(cost=cost, limit=limit, d_min=1, d_max=25, rows=rows, uniqueness=uniqueness, lr_check=lr_check,
              max_matches=1023)
    listed, total, cands = loop_reference(fl, fr, a, b, **kw)
    res = E.match_engine(fl, fr, a, b, width=60, window=window, **kw)
    got = list(zip(res["left_index"].tolist(), res["right_index"].tolist(), res["dy"].tolist(),
                   res["matches"][:, 2].tolist(), res["matches"][:, 3].tolist()))
    assert got == listed
    assert (res["total"], res["candidates"]) == (total, cands)
    assert total > 0  # the case exercises something


def test_max_matches_cuts_the_list_like_the_rules():
    fl, fr, a, b = random_case(3, "sad", 5)
    kw = dict(cost="sad", limit=4000, d_min=0, d_max=40, rows=2, uniqueness=0, lr_check=False)
    listed, total, _ = loop_reference(fl, fr, a, b, max_matches=5, **kw)
    res = E.match_engine(fl, fr, a, b, width=60, window=5, max_matches=5, **kw)
    assert total > 5 and res["count"] == 5 and res["overflow"]
    assert res["left_index"].tolist() == [m[0] for m in listed]
    marker, count, cands = (w for w, _, _ in res["words"][-3:])
    assert (marker, count) == (E.MARKER, 5 | 1 << 15)


def test_sad_words_are_the_window_columns_top_pixel_lowest():
    win = np.arange(25).reshape(1, 25) * 10  # row i: 50i, 50i + 10, ..., 50i + 40; column k: 10k, 10k + 50, ...
    words = E.pack_descriptors(win, "sad", 5)
    assert words[0][0] == 0 | 50 << 8 | 100 << 16 | 150 << 24 | 200 << 32
    assert words[0][4] == 40 | 90 << 8 | 140 << 16 | 190 << 24 | 240 << 32
    assert len(words[0]) == E.descriptor_words("sad", 5) and E.word_bits("sad", 5) == 40


@pytest.mark.parametrize("window", [5, 7])
def test_census_word_is_the_census_models_word(window):
    img = np.random.default_rng(window).integers(0, 256, (20, 24)).astype(np.uint8)
    xy = np.array([[3, 4], [10, 10], [0, 0], [23, 19]], np.int64)  # two inside, two on corners of the frame
    r = window // 2
    pad = np.pad(img.astype(np.int16), r, constant_values=256)
    off = np.arange(window)
    win = pad[xy[:, 1, None, None] + off[None, :, None], xy[:, 0, None, None] + off[None, None, :]].reshape(4, -1)
    centre = window * window // 2
    bits = np.delete(win < win[:, centre:centre + 1], centre, axis=1)
    words = [w[0] for w in E.pack_descriptors(bits, "census", window)]
    full = C.census(img, window=window)
    assert words == [int(full[y, x]) for x, y in xy]
    assert E.word_bits("census", window) == window * window - 1


@pytest.mark.parametrize("window", [9, 11])
def test_wide_census_words_keep_every_bit(window):
    """80- and 120-bit words (wider than int64): bit i of the window's raster order is bit nb - 1 - i."""
    nb = window * window - 1
    bits = np.zeros((3, nb), bool)
    bits[0, 0] = True  # the top-left neighbour: the most significant bit
    bits[1, nb - 1] = True
    bits[2, :] = True
    words = [w[0] for w in E.pack_descriptors(bits, "census", window)]
    assert words == [1 << (nb - 1), 1, (1 << nb) - 1]


def test_order_key_sorts_like_the_tuple_rule():
    rng = np.random.default_rng(0)
    cost, dy, d = rng.integers(0, 30855, 500), rng.integers(-7, 8, 500), rng.integers(0, 256, 500)
    cost[::7] = 100  # ties on cost
    keys = E.order_key(cost, dy, d)
    by_key = np.argsort(keys, kind="stable")
    by_tuple = sorted(range(500), key=lambda i: (cost[i], abs(dy[i]), d[i], dy[i]))
    assert by_key.tolist() == by_tuple
    assert E.KEY.width == 30


@pytest.mark.parametrize("change,match", [
    (dict(limit=0), "limit=0"), (dict(limit=4097), "limit=4097"), (dict(d_min=5, d_max=4), "empty"),
    (dict(rows=8), "rows=8"), (dict(window=6), "window=6"), (dict(cost="ssd"), "cost"),
    (dict(uniqueness=100), "uniqueness"), (dict(max_matches=0), "max_matches"), (dict(d_max=256), "8-bit"),
    (dict(limit=3.0), "integer"),
])
def test_bad_settings(change, match):
    kw = dict(cost="sad", window=5, limit=100, d_min=0, d_max=64, rows=0, uniqueness=0, max_matches=10)
    with pytest.raises(ValueError, match=match):
        E.check_engine(**dict(kw, **change))


def test_parse_list_reads_back_the_model_words():
    rng = np.random.default_rng(4)
    fl = np.array([[10, 3], [20, 3], [30, 5]], np.int64)
    fr = np.array([[7, 3], [15, 3], [26, 5]], np.int64)
    a = rng.integers(0, 256, (3, 25))
    res = E.match_engine(fl, fr, a, a.copy(), width=64, window=5, limit=4096, max_matches=2)
    got = E.parse_list(res["words"])
    assert got["matches"].tolist() == res["matches"].tolist() and got["dy"].tolist() == res["dy"].tolist()
    assert (got["count"], got["overflow"], got["candidates"]) == (res["count"], res["overflow"], res["candidates"])
    with pytest.raises(ValueError, match="not a match list"):
        E.parse_list([1, 2, 3, 4])
