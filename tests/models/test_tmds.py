"""The video models: TMDS encoding against DVI 1.0 worked by hand, the modes against the published tables, the
serializer's bit order, and the DVI receiver (alignment from any bit, its errors on broken streams)."""

from __future__ import annotations

import numpy as np
import pytest

from eyestereo.tools.models import dvi_receiver as rx
from eyestereo.tools.models.tmds_encoder import (CONTROL, DATA_SYMBOLS, DISPARITY_BOUND, decode, encode, encode_stream,
                                                 transition_minimise)
from eyestereo.tools.models.tmds_serializer import CLOCK_WORD, ddr_pairs, load_edge, pairs_to_bits, serial_bits
from eyestereo.tools.models.video_timing import MODES, VideoMode, mode_of, signals


# --- the encoder against DVI 1.0 section 3.2.2, worked by hand ------------------------------------------------
def test_control_codes_are_the_spec_table():
    # DVI 1.0 3.2.2: (C1, C0) = 00, 01, 10, 11 -> q_out[9:0]
    de = np.zeros(4, dtype=int)
    q = encode_stream([0x5A] * 4, c0=[0, 1, 0, 1], c1=[0, 0, 1, 1], de=de)
    assert q.tolist() == [0b1101010100, 0b0010101011, 0b0101010100, 0b1010101011]
    assert [decode(c) for c in q.tolist()] == [(False, 0), (False, 1), (False, 2), (False, 3)]


# Each row: byte, disparity before, character, disparity after -- worked through the spec's flow chart by hand:
# 0x00: 0 ones -> XOR chain, q_m = 1_00000000 (q_m[8] = 1), N1 = 0, N0 = 8.
#   cnt 0: "cnt = 0 or N1 = N0" branch: q_out = ~q_m[8], q_m[8], q_m[7:0] = 0 1 00000000; cnt += N1 - N0 = -8
#   cnt -8: cnt < 0 and N0 > N1: complement: q_out = 1 1 11111111; cnt += 2 q_m[8] + N0 - N1 = -8 + 2 + 8 = 2
#   cnt 2: neither: q_out = 0 1 00000000; cnt += -2 (1 - q_m[8]) + N1 - N0 = 2 - 0 - 8 = -6
# 0xFF: 8 ones -> XNOR chain, q_m = 0_11111111, N1 = 8.
#   cnt 0: q_out = ~q_m[8], q_m[8], ~q_m[7:0] = 1 0 00000000; cnt += N0 - N1 = -8
#   cnt -8: neither: q_out = 0 0 11111111; cnt += -2 + 8 = -2; cnt -2: the same again, -2 - 2 + 8 = 4
#   cnt 4: cnt > 0 and N1 > N0: complement: 1 0 00000000; cnt += 0 + 0 - 8 = -4
# 0x10 = 00010000: 1 one -> XOR: q_m[3:0] = 0, q_m[7:4] = 1111 -> q_m = 1_11110000, N1 = N0 = 4:
#   q_out = 0 1 11110000, cnt stays 0
# 0x55 = 01010101: 4 ones and D[0] = 1 -> XOR: q_m[7:0] = 00110011, q_m[8] = 1: q_out = 0 1 00110011, cnt 0
# 0xAA = 10101010: 4 ones and D[0] = 0 -> XNOR: q_m[7:0] = 11001100, q_m[8] = 0: q_out = 1 0 00110011, cnt 0
# 0x01: 1 one -> XOR: q_m = 1_11111111, N1 = 8. cnt 0: 0 1 11111111, cnt 8; cnt 8: cnt > 0 and N1 > N0:
#   1 1 00000000, cnt += 2 + 0 - 8 = 2
HAND = [
    (0x00, 0, 0b0100000000, -8), (0x00, -8, 0b1111111111, 2), (0x00, 2, 0b0100000000, -6),
    (0xFF, 0, 0b1000000000, -8), (0xFF, -8, 0b0011111111, -2), (0xFF, -2, 0b0011111111, 4),
    (0xFF, 4, 0b1000000000, -4),
    (0x10, 0, 0b0111110000, 0), (0x55, 0, 0b0100110011, 0), (0xAA, 0, 0b1000110011, 0),
    (0x01, 0, 0b0111111111, 8), (0x01, 8, 0b1100000000, 2),
]


@pytest.mark.parametrize("d,cnt,q,cnt_after", HAND)
def test_encoder_matches_hand_worked_examples(d, cnt, q, cnt_after):
    assert encode(d, cnt) == (q, cnt_after)


def test_a_stream_carries_the_disparity_and_control_restarts_it():
    # 0x00 three times from 0 (the rows above), a control character (cnt back to 0), 0x00 again = the first row
    q = encode_stream([0, 0, 0, 0x77, 0], c0=[0, 0, 0, 1, 0], c1=[0] * 5, de=[1, 1, 1, 0, 1])
    assert q.tolist() == [0b0100000000, 0b1111111111, 0b0100000000, 0b0010101011, 0b0100000000]


@pytest.mark.parametrize("cnt", range(-DISPARITY_BOUND, DISPARITY_BOUND + 1, 2))
def test_decode_inverts_encode_for_every_byte(cnt):
    for d in range(256):
        q, _ = encode(d, cnt)
        assert decode(q) == (True, d), (d, cnt)
        assert q not in CONTROL


def test_transition_minimising_leaves_at_most_three_transitions():
    # XOR is chosen for at most 3 ones in D[7:1] (each 1 is a transition of the chain), XNOR for at most 3 zeros
    for d in range(256):
        m = transition_minimise(d) & 0xFF
        assert sum((m >> i ^ m >> (i + 1)) & 1 for i in range(7)) <= 3, d


def test_disparity_states_are_bounded():
    # every state reachable from 0 by any byte sequence (breadth first): the even numbers -8 .. 8
    seen, todo = {0}, [0]
    while todo:
        c = todo.pop()
        for d in range(256):
            nxt = encode(d, c)[1]
            if nxt not in seen:
                seen.add(nxt)
                todo.append(nxt)
    assert sorted(seen) == list(range(-8, 9, 2)) and DISPARITY_BOUND == 8


def test_the_sent_bits_stay_dc_balanced_on_random_data():
    """The disparity counted on the characters' own bits (ones minus zeros of all ten), not the model's cnt:
    at every character boundary within +-8, over random bytes and runs of one byte."""
    rng = np.random.default_rng(7)
    data = rng.integers(0, 256, 20000)
    data[5000:7000] = 0x00
    data[9000:11000] = 0xFF
    q = encode_stream(data, 0, 0, 1)
    ones = np.array([bin(c).count("1") for c in q.tolist()])
    running = np.cumsum(2 * ones - 10)
    assert np.abs(running).max() <= 8
    assert len(DATA_SYMBOLS) == 460 and set(q.tolist()) <= DATA_SYMBOLS


# --- modes and timing ------------------------------------------------------------------------------------------
def test_640x480_is_the_published_mode():
    # VESA DMT 640x480@60 (ID 04h, borders folded in) = CEA-861-D format 1: H 640/16/96/48, V 480/10/2/33, both -
    m = MODES["640x480@60"]
    assert (m.h_active, m.h_front, m.h_sync, m.h_back, m.h_pol) == (640, 16, 96, 48, False)
    assert (m.v_active, m.v_front, m.v_sync, m.v_back, m.v_pol) == (480, 10, 2, 33, False)
    assert (m.h_total, m.v_total) == (800, 525)
    assert m.frame_rate() == pytest.approx(59.94, abs=0.005)  # 25.175 MHz: the published 59.94 Hz
    assert m.frame_rate(25e6) == pytest.approx(59.52, abs=0.005)  # the board's 25.0 MHz


@pytest.mark.parametrize("name", sorted(MODES))
def test_timing_signals_count_what_the_mode_says(name):
    m = MODES[name]
    s = signals(m, 2 * m.frame_clocks)
    lines = {k: v.reshape(2 * m.v_total, m.h_total) for k, v in s.items()}
    assert s["de"].sum() == 2 * m.h_active * m.v_active
    on = int(m.h_pol)
    assert ((lines["hsync"] == on).sum(axis=1) == m.h_sync).all()
    assert ((lines["vsync"] == int(m.v_pol)).sum() == 2 * m.v_sync * m.h_total)
    assert s["line_start"].sum() == 2 * m.v_active and s["frame_start"].sum() == 2
    first = int(np.argmax(s["de"]))  # the first pixel: after the vertical sync and back porch, the h ones
    assert first == (m.v_sync + m.v_back) * m.h_total + m.h_sync + m.h_back
    xs, ys = s["x"][s["de"] == 1], s["y"][s["de"] == 1]
    assert xs[:m.h_active].tolist() == list(range(m.h_active)) and ys.max() == m.v_active - 1
    assert (s["x"][s["de"] == 0] == 0).all() and (s["y"][s["de"] == 0] == 0).all()


def test_modes_refuse_nonsense():
    with pytest.raises(ValueError, match="unknown video mode 'vga'; the modes are"):
        mode_of("vga")
    with pytest.raises(ValueError, match="h_sync must be a positive integer"):
        VideoMode("bad", 8, 1, 0, 1, 8, 1, 1, 1, h_pol=True, v_pol=True, pixel_mhz=1.0)


# --- serializer bit order --------------------------------------------------------------------------------------
def test_serializer_sends_bit_0_first_in_pairs():
    assert serial_bits([CLOCK_WORD]).tolist() == [1, 1, 1, 1, 1, 0, 0, 0, 0, 0]
    assert serial_bits([0b1101010100]).tolist() == [0, 0, 1, 0, 1, 0, 1, 0, 1, 1]
    # pair k = (bit 2k in bit 0: the DDR cell's D0, rising edge; bit 2k + 1 in bit 1: D1, falling edge)
    assert ddr_pairs([0b1101010100]).tolist() == [0b00, 0b01, 0b01, 0b01, 0b11]
    assert pairs_to_bits([0b01, 0b10]).tolist() == [1, 0, 0, 1]


def test_load_edge_is_the_third_fast_edge_after():
    # pixel edge at 40 ns, fast edges at 2 + 8 k ns: the first after it is k = 5 (42 ns), the third k = 7
    assert load_edge(40000, 2000, 8000) == 7
    assert load_edge(40000, 7000, 8000) == 7  # 47 ns is k = 5 again
    with pytest.raises(ValueError, match="coincides"):
        load_edge(40000, 0, 8000)


# --- the DVI receiver ------------------------------------------------------------------------------------------
def _link(mode, frames=2, seed=0, tamper=None):
    """(the three channels' bit streams, the whole frames' images, the characters): frames of random images,
    from two lines before a frame ends; ``tamper(signals)`` may change the timing before the encoding."""
    m = MODES[mode]
    start = m.frame_clocks - 2 * m.h_total
    n = frames * m.frame_clocks + 3 * m.h_total
    s = signals(m, n, start)
    if tamper is not None:
        tamper(s)
    images = np.random.default_rng(seed).integers(0, 256, (frames + 2, m.v_active, m.h_active, 3))
    rgb = images[np.arange(start, start + n) // m.frame_clocks, s["y"], s["x"]]
    words = [encode_stream(rgb[:, 2], s["hsync"], s["vsync"], s["de"]), encode_stream(rgb[:, 1], 0, 0, s["de"]),
             encode_stream(rgb[:, 0], 0, 0, s["de"])]
    return [serial_bits(w) for w in words], images[1:frames + 1].astype(np.uint8), words


@pytest.mark.parametrize("cut", range(10))
def test_receiver_finds_the_boundary_from_any_bit(cut):
    bits, images, _ = _link("sim-32x24")
    cap = rx.receive([b[cut + 20:] for b in bits], "sim-32x24")
    assert cap.offsets == ((10 - cut) % 10,) * 3 and cap.skew == (0, 0, 0)
    assert len(cap.frames) == 2 and all(np.array_equal(a, b) for a, b in zip(cap.frames, images, strict=True))


def test_receiver_deskews_channels_cut_at_different_bits():
    bits, images, _ = _link("sim-64x48", frames=1, seed=3)
    cap = rx.receive([bits[0][7:], bits[1][23:], bits[2][31:]], "sim-64x48")
    # the first whole characters are the sent ones 1 (bit 10), 3 (bit 30) and 4 (bit 40): channel 0 drops 3
    # characters and channel 1 drops 1 to line up with channel 2
    assert cap.offsets == (3, 7, 9) and cap.skew == (3, 1, 0)
    assert len(cap.frames) == 1 and np.array_equal(cap.frames[0], images[0])


def test_receiver_reads_a_whole_640x480_frame():
    bits, images, _ = _link("640x480@60", frames=1, seed=1)
    cap = rx.receive([b[1234:] for b in bits], "640x480@60")
    assert cap.timing["h_total"] == 800 and cap.timing["h_sync"] == 96 and cap.timing["v_sync"] == 2
    assert len(cap.frames) == 1 and np.array_equal(cap.frames[0], images[0])


def test_receiver_rejects_a_flipped_bit():
    bits, _, words = _link("sim-32x24")
    # a data character of channel 1 whose one flipped bit is neither a control nor a data character
    k = int(np.nonzero(~np.isin(words[1], CONTROL))[0][500])
    bit = next(b for b in range(10) if (words[1][k] ^ 1 << b) not in DATA_SYMBOLS | set(CONTROL))
    broken = bits[1].copy()
    broken[10 * k + bit] ^= 1
    with pytest.raises(rx.DviError, match=rf"^channel 1, character {k - 5} \(bit {10 * (k - 5)}\): 0b\d+ is "
                                          r"neither a control code nor a TMDS data character \(invalid symbol\)$"):
        rx.receive([bits[0][50:], broken[50:], bits[2][50:]], "sim-32x24")


def test_receiver_rejects_a_valid_character_at_the_wrong_disparity():
    bits, _, words = _link("sim-32x24")
    ch = words[2].copy()
    for k in np.nonzero(~np.isin(ch, CONTROL))[0][40:].tolist():
        d = decode(int(ch[k]))[1]
        other = {encode(d, c)[0] for c in range(-8, 9, 2)} - {int(ch[k])}
        if other:  # the same byte, the other polarity: a valid symbol that breaks the DC balance
            ch[k] = other.pop()
            break
    with pytest.raises(rx.DviError, match=r"^channel 2, .*carries byte .* at the wrong DC balance"):
        rx.receive([bits[0], bits[1], serial_bits(ch)], "sim-32x24")


def test_receiver_rejects_a_wrong_hsync_width():
    m = MODES["sim-32x24"]

    def longer(s):  # the 5th horizontal sync pulse one clock longer
        hs = s["hsync"] == int(m.h_pol)
        end = int(np.nonzero(hs[:-1] & ~hs[1:])[0][4]) + 1
        s["hsync"][end] = int(m.h_pol)

    bits, _, _ = _link("sim-32x24", tamper=longer)
    with pytest.raises(rx.DviError, match=rf"^horizontal sync pulse {m.h_sync + 1} characters wide at character "
                                          rf"\d+ \(bit \d+\): mode sim-32x24 says {m.h_sync}$"):
        rx.receive(bits, "sim-32x24")


def test_receiver_rejects_a_short_line_and_the_wrong_mode():
    def short(s):  # the last pixel of the 30th active line blanked
        de = s["de"] == 1
        s["de"][int(np.nonzero(de[:-1] & ~de[1:])[0][29])] = 0

    bits, _, _ = _link("sim-32x24", tamper=short)
    with pytest.raises(rx.DviError, match=r"^DE run of 31 characters .*: mode sim-32x24 has 32 active pixels"):
        rx.receive(bits, "sim-32x24")
    bits, _, _ = _link("sim-32x24")
    with pytest.raises(rx.DviError, match=r"^DE run of 32 characters .*: mode sim-64x48 has 64 active pixels"):
        rx.receive(bits, "sim-64x48")


def test_receiver_rejects_a_late_vertical_sync():
    m = MODES["sim-32x24"]

    def late(s):  # the second vertical sync pulse one line late (front porch 3 lines, back porch 2)
        vs = np.nonzero(s["vsync"] == int(m.v_pol))[0]
        first = vs[vs > m.frame_clocks][0]
        s["vsync"][first:first + m.h_total] = int(not m.v_pol)
        s["vsync"][first + m.v_sync * m.h_total:first + (m.v_sync + 1) * m.h_total] = int(m.v_pol)

    bits, _, _ = _link("sim-32x24", frames=3, tamper=late)
    with pytest.raises(rx.DviError, match=r"^vertical front porch of 3 lines before the vertical sync at character "
                                          r"\d+ \(bit \d+\): mode sim-32x24 says 2$"):
        rx.receive(bits, "sim-32x24")


def test_receiver_needs_blanking():
    rng = np.random.default_rng(0)
    data = encode_stream(rng.integers(0, 256, 500), 0, 0, [1] * 500)
    with pytest.raises(rx.DviError, match="^channel 0: no symbol boundary found"):
        rx.receive([serial_bits(data)] * 3, "sim-32x24")
