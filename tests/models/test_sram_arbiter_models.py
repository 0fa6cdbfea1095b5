"""The arbiter's Python models: address map, fetch addresses, double-buffer rules, buffer history, scoreboard."""

import pytest

from eyestereo.tools.models.sram_arbiter import (CAMERA_WORD, FREE, FULL, READING, RECT_WORD, STAT, WRITING,
                                                 AddressMap, BufferHistory, DoubleBufferModel, Scoreboard,
                                                 fetch_addresses)
from eyestereo.tools.sram import power_up_word


def test_address_map_of_the_thesis_board_fits():
    m = AddressMap()
    n = 352 * 288
    assert m.frame == n == 101_376
    assert [m.camera(c, b) for c in (0, 1) for b in (0, 1)] == [0, n, 2 * n, 3 * n]
    assert (m.rectified(0), m.rectified(1)) == (4 * n, 5 * n)
    assert m.features(0) == 6 * n and m.features(1) == 6 * n + 8192
    assert m.host_base == 6 * n + 2 * 8192 <= 1 << 20
    regions = m.regions()
    # contiguous, no overlap, up to the last word
    for (_, a, k), (_, b, _) in zip(regions, regions[1:]):
        assert a + k == b
    assert regions[-1][1] + regions[-1][2] == 1 << 20
    assert "| camera 0 buffer 0 | 0x00000 |" in m.table()


@pytest.mark.parametrize("kw,msg", [(dict(width=640, height=480), "need"), (dict(feature_words=1), "feature_words"),
                                    (dict(width=2.5), "width")])
def test_address_map_rejects_what_does_not_fit(kw, msg):
    with pytest.raises(ValueError, match=msg):
        AddressMap(**kw)


def test_fetch_addresses_order_and_offsets():
    m = AddressMap(10, 5)
    base = m.camera(1, 0)
    got = fetch_addresses(m, base, 3, 2, 0b1111)
    assert got == [(0, base + 3 * 10 + 4), (1, base + 3 * 10 + 3), (2, base + 2 * 10 + 4), (3, base + 2 * 10 + 3)]
    assert fetch_addresses(m, base, 3, 2, 0b1010) == [(1, base + 33), (3, base + 23)]
    with pytest.raises(ValueError, match="outside"):
        fetch_addresses(m, base, 9, 0, 0b0100)
    with pytest.raises(ValueError, match="mask"):
        fetch_addresses(m, base, 0, 0, 0)


def test_words_are_declared_once():
    assert CAMERA_WORD.width == RECT_WORD.width == 16
    assert int(RECT_WORD.pack(left=0x12, right=0x34)) == 0x3412
    assert int(CAMERA_WORD.unpack(0xAB55)["y"]) == 0x55
    assert len(STAT) == 22 and STAT[12] == "clocks since reset"


def test_double_buffer_rules():
    m = DoubleBufferModel()
    m.clock(p_start=True)                       # FREE, FREE: buffer 1 (not the newest, 0)
    assert m.p_grant and m.p_gbuf == 1 and m.state == [FREE, WRITING]
    m.clock(p_start=True)                       # the answer's clock: not asked again
    assert not m.p_grant and m.state == [FREE, WRITING]
    m.clock(p_done=True, p_done_buf=1)
    assert m.state == [FREE, FULL] and m.newest == 1 and m.c_avail()
    m.clock(p_start=True)                       # a FREE buffer is preferred to the FULL one
    assert m.p_gbuf == 0 and m.state == [WRITING, FULL]
    m.clock(c_take=True)                        # the consumer takes the newest FULL
    assert m.held and m.buf == 1 and m.state == [WRITING, READING]
    m.clock(p_done=True, p_done_buf=0)
    m.clock(p_start=True)                       # the only candidate is buffer 0 (FULL): overwritten
    assert m.p_grant and m.p_gbuf == 0 and m.overwritten == 1
    m.clock(c_release=True)
    assert not m.held and m.state == [WRITING, FREE]


def test_take_wins_over_a_producer_in_the_same_clock():
    m = DoubleBufferModel(state=[FULL, WRITING], newest=0)
    m.clock(p_start=True, c_take=True)          # buffer 0 goes to the consumer; the producer finds none
    assert m.held and m.buf == 0 and m.p_deny and m.dropped == 1 and m.state == [READING, WRITING]


def test_buffer_history_rebuilds_frames_and_catches_half_written_reads():
    sent = [[10, 11, 12], [20, 21, 22], [30, 31, 32]]
    writes = [(1, 100, 10), (2, 101, 11), (3, 102, 12),      # frame 0 into buffer 0 (base 100)
              (5, 200, 30), (6, 201, 31)]                     # frame 1 dropped; frame 2 half in buffer 1
    h = BufferHistory("cam", (100, 200), 3, writes, sent)
    assert [(r.buf, r.item, r.complete) for r in h.runs] == [(0, 0, True), (1, 2, False)]
    assert h.word_at(4, 101) == 11
    with pytest.raises(AssertionError, match="half-written"):
        h.word_at(7, 200)
    with pytest.raises(AssertionError, match="nothing was written"):
        h.word_at(0, 100)
    with pytest.raises(AssertionError, match="does not continue"):
        BufferHistory("cam", (100, 200), 3, [(1, 101, 11)], sent)
    with pytest.raises(AssertionError, match="matches no frame"):
        BufferHistory("cam", (100, 200), 3, [(1, 100, 99)], sent)


def test_scoreboard_bytes_and_power_up():
    sb = Scoreboard()
    assert sb.read(7) == power_up_word(7)
    sb.write(7, 0xAAAA, be=3)
    sb.write(7, 0x5555, be=1)
    assert sb.read(7) == 0xAA55
    sb.write(7, 0x1200, be=2)
    assert sb.peek(7) == 0x1255 and sb.writes == 3 and sb.reads == 2


def test_the_map_without_camera_buffers():
    """cameras=False (rectify="stream"): the rectified buffers from 0, the lists after them; VGA fits the 1M words
    (2 x 307,200 + 2 x 8,192 = 630,784), which it does not with the camera buffers (6 x 307,200 = 1,843,200)."""
    m = AddressMap(640, 480, 8192, cameras=False)
    assert (m.rectified(0), m.rectified(1)) == (0, 307_200)
    assert (m.features(0), m.features(1)) == (614_400, 622_592) and m.host_base == 630_784
    assert m.bases("cam0") == (0, 0)
    with pytest.raises(ValueError, match="no camera buffers"):
        m.camera(0, 0)
    assert [r[0] for r in m.regions()][:2] == ["rectified buffer 0", "rectified buffer 1"]
    with pytest.raises(ValueError, match="need 1859584 words"):
        AddressMap(640, 480, 8192)


def test_the_map_with_disparity_buffers():
    """dense=True (the front end's dense option): two disparity buffers of a frame each after the feature lists,
    the host area after them; CIF fits (8 frames + 2 lists = 827,392 words), VGA does not; the map without them has
    none."""
    m = AddressMap(352, 288, 8192, dense=True)
    f = 352 * 288
    assert m.disparity(0) == 6 * f + 2 * 8192 and m.disparity(1) == 7 * f + 2 * 8192
    assert m.bases("disp") == (m.disparity(0), m.disparity(1)) and m.host_base == 8 * f + 2 * 8192
    assert [r[0] for r in m.regions()][8:11] == ["disparity buffer 0", "disparity buffer 1", "host area"]
    with pytest.raises(ValueError, match="no disparity buffers"):
        AddressMap(352, 288, 8192).disparity(0)
    s = AddressMap(352, 288, 8192, cameras=False, dense=True)  # the line cache's map: the maps after the lists
    assert s.disparity(0) == 2 * f + 2 * 8192 and s.host_base == 4 * f + 2 * 8192
    # VGA does not fit the 1M words with the maps, even without the camera buffers (4 x 307,200 + the lists)
    with pytest.raises(ValueError, match="4 buffers of 307200 words and 2 feature lists of 8192 need 1245184"):
        AddressMap(640, 480, 8192, cameras=False, dense=True)
