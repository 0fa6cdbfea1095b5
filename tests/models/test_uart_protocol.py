"""The UART models and the bridge's protocol: hand-worked byte examples, the host's encoder and decoder, and
SerialBus driving the bridge's model through a fake transport (reads, writes, bursts, a timeout)."""

import asyncio

import pytest

from eyestereo.tools.board import protocol as P
from eyestereo.tools.board.serial_bus import READ_PIECE, SerialBus
from eyestereo.tools.models.uart_bridge import DROPPED, PAUSE, Access, UartBridge, uart_bridge
from eyestereo.tools.models.uart_rx import sample, uart_rx, waveform
from eyestereo.tools.models.uart_tx import frame_bits, line, uart_tx


class Regs:
    """A bus of 4 words at 0x10..0x1c (the rest SLVERR), logging nothing: the test states every value."""

    def __init__(self):
        self.words = {0x10: 0x11223344, 0x14: 0xA5A5A5A5, 0x18: 0, 0x1C: 0xFFFFFFFF}

    def read(self, address):
        if address in self.words:
            return self.words[address], 0
        return 0, 2

    def write(self, address, data, strb):
        if address not in self.words:
            return 2
        mask = sum(0xFF << 8 * i for i in range(4) if strb >> i & 1)
        self.words[address] = self.words[address] & ~mask | data & mask
        return 0


# --------------------------------------------------------------------------------------------------
# bit level


def test_frame_bits_hand_worked():
    # 0x4B = 0100 1011: LSB first 1,1,0,1,0,0,1,0 between start 0 and stop 1
    assert frame_bits(0x4B) == [0, 1, 1, 0, 1, 0, 0, 1, 0, 1]
    assert line([0x80], 2, idle_before=1) == [1] + [0, 0] + [0] * 14 + [1, 1] + [1, 1]


def test_tx_model_back_to_back_and_waiting():
    # byte 0 offered at edge 0 (taken there), byte 1 waiting: taken in the last clock of byte 0's stop bit,
    # 10 bits x 8 clocks later; byte 2 offered 100 clocks after that take, when the line is idle again
    takes, trans = uart_tx([(0, 0x00), (0, 0xFF), (100, 0x55)], 8)
    assert takes == [0, 80, 181]
    assert trans[:3] == [(0, 0), (72, 1), (80, 0)]  # start of 0x00, its stop bit, start of 0xFF
    assert trans[3] == (88, 1)  # 0xFF's data bits are all 1: no transition until the next start bit
    assert trans[4] == (181, 0)


@pytest.mark.parametrize("cpb", [8, 13, 33, 868])
@pytest.mark.parametrize("skew", [-0.03, 0.0, 0.03])
def test_rx_model_reads_a_sender_off_in_baud(cpb, skew):
    """Bytes back to back from a sender 3 % off: the model decodes exactly the bytes sent (the reference)."""
    data = [0x00, 0xFF, 0x55, 0xAA, 0x01, 0x80, 0x3C, 0xC3]
    period = 1000
    trans, end = waveform(data, cpb * period * (1 + skew), start=7 * period + 1)
    n = int(end / period) + 4 * cpb
    events = uart_rx(sample(trans, [k * period for k in range(n)]), cpb)
    assert [e[2] for e in events if e[1] == "byte"] == data
    assert not [e for e in events if e[1] != "byte"]


@pytest.mark.parametrize("cpb", [8, 33])
def test_rx_model_glitch_framing_and_break(cpb):
    period = 1000
    half = cpb * period // 2
    g1 = [(10.5 * period, 0), (10.5 * period + half - 1, 1)]  # a glitch just under half a bit: nothing
    bad, t = waveform([0x12], cpb * period, start=40 * cpb * period + 1, stop_bits=[0])  # framing error
    good, t2 = waveform([0x34], cpb * period, start=t + 3 * cpb * period + 1)
    brk = [(t2 + 2 * cpb * period + 1, 0), (t2 + 40 * cpb * period + 1, 1)]  # a long break: one error
    events = uart_rx(sample(g1 + bad + good + brk, [k * period for k in range(int(t2) // period + 60 * cpb)]), cpb)
    assert [e[1:] for e in events] == [("framing", None), ("byte", 0x34), ("framing", None)]


# --------------------------------------------------------------------------------------------------
# the bridge's model against hand-worked bytes


def test_bridge_model_hand_worked_example():
    regs = Regs()
    items = [0x49,                                           # identify
             0x52, 0x00, 0x00, 0x00, 0x10, 0x01,             # read 2 words at 0x10
             0x57, 0x01, 0x00, 0x00, 0x18, 0x01, 0x03,       # write 2 words at 0x1000018 (bit 24 ignored), strb 3
             0xDE, 0xAD, 0xBE, 0xEF, 0x01, 0x02, 0x03, 0x04,
             0x52, 0x00, 0x00, 0x00, 0x20, 0x00,             # read 1 word at 0x20: SLVERR
             0x00,                                           # unknown
             DROPPED,                                        # a framing error
             0x57, 0x00, 0x00,                               # a write cut off
             PAUSE,
             0x49]
    reply, accesses, errors = uart_bridge(items, regs, addr_bits=24)
    assert reply == bytes([0x69, 0x45, 0x53, 0x42, 0x31,
                           0x72, 0x00, 0x11, 0x22, 0x33, 0x44, 0x00, 0xA5, 0xA5, 0xA5, 0xA5,
                           0x77, 0x00, 0x00,
                           0x72, 0x02, 0x00, 0x00, 0x00, 0x00,
                           0x3F, 0x00,
                           0x3F, 0x54,
                           0x69, 0x45, 0x53, 0x42, 0x31])
    assert accesses == [Access("R", 0x10, 0x11223344, 0, 0), Access("R", 0x14, 0xA5A5A5A5, 0, 0),
                        Access("W", 0x18, 0xDEADBEEF, 3, 0), Access("W", 0x1C, 0x01020304, 3, 0),
                        Access("R", 0x20, 0, 0, 2)]
    assert regs.words[0x18] == 0x0000BEEF and regs.words[0x1C] == 0xFFFF0304
    assert errors == 3  # the unknown byte, the framing error, the abandoned write


def test_bridge_model_address_wraps_and_pause_outside_a_request_is_nothing():
    seen = []

    class Bus:
        def read(self, address):
            seen.append(address)
            return address, 0

    m = UartBridge(Bus(), addr_bits=8)
    m.feed([PAUSE, 0x52, 0xFF, 0xFF, 0xFF, 0xF8, 0x02, PAUSE])
    assert seen == [0xF8, 0xFC, 0x00]
    assert m.errors == 0 and m.reply[0] == 0x72 and len(m.reply) == 16


def test_bridge_model_errors_saturate():
    m = UartBridge(Regs())
    m.feed([DROPPED] * 70000)
    assert m.errors == 0xFFFF


# --------------------------------------------------------------------------------------------------
# the host's encoder and decoder


def test_encoders_hand_worked():
    assert P.encode_identify() == b"I"
    assert P.encode_read(0x400010, 3) == bytes([0x52, 0x00, 0x40, 0x00, 0x10, 0x02])
    assert P.encode_write(0x8, [0x01020304], strb=0x5) == bytes([0x57, 0, 0, 0, 8, 0, 5, 1, 2, 3, 4])
    assert P.reply_length(P.encode_read(0, 256)) == 1 + 5 * 256
    assert P.reply_length(P.encode_write(0, [0] * 3)) == 4


@pytest.mark.parametrize("call,match", [
    (lambda: P.encode_read(0, 257), r"words per request 0x101 does not fit"),
    (lambda: P.encode_read(0, 0), r"words per request 0x0 does not fit"),
    (lambda: P.encode_read(1 << 32), r"address 0x100000000 does not fit"),
    (lambda: P.encode_write(0, [1 << 32]), r"data word"),
    (lambda: P.encode_write(0, [1], strb=16), r"strb 0x10 does not fit"),
    (lambda: P.encode_read(1.0), r"address must be an integer, got float"),
])
def test_encoders_refuse_what_does_not_fit(call, match):
    with pytest.raises(ValueError, match=match):
        call()


@pytest.mark.parametrize("reply,match", [
    (bytes([0x3F, 0x54]), r"read: the board answered '\?' \(the request timed out on the board\)"),
    (bytes([0x3F, 0x52]), r"byte 0x52 not understood"),
    (bytes([0x77, 0]), r"reply code 0x77, expected 0x72"),
    (bytes([0x72, 0, 1, 2]), r"read: 4 reply bytes, expected 6"),
])
def test_decoder_refuses_wrong_replies(reply, match):
    with pytest.raises(P.ProtocolError, match=match):
        P.decode_read(reply, 1)


# --------------------------------------------------------------------------------------------------
# SerialBus through a fake transport on the model


class FakePort:
    """pyserial's interface on the bridge's model: ``write`` feeds it, ``read`` returns its reply bytes
    (fewer when the board has no more: a timeout). ``mute``: the board does not answer at all."""

    def __init__(self, bus, *, mute=False):
        self.model = UartBridge(bus)
        self.taken = 0
        self.mute = mute
        self.reads: list[int] = []

    def write(self, data):
        if not self.mute:
            self.model.feed(data)
        return len(data)

    def read(self, n):
        self.reads.append(n)
        out = bytes(self.model.reply[self.taken:self.taken + n])
        self.taken += len(out)
        return out


def test_serial_bus_reads_writes_and_bursts():
    regs = Regs()
    port = FakePort(regs)
    bus = SerialBus(port)

    async def run():
        assert await bus.identify() == 0x45534231
        assert await bus.read(0x10) == (0x11223344, 0)
        assert await bus.write(0x18, 0x0000ABCD, strb=0x3) == 0
        assert await bus.read_burst(0x14, 4) == [(0xA5A5A5A5, 0), (0xABCD, 0), (0xFFFFFFFF, 0), (0, 2)]
        assert await bus.write_burst(0x1C, [7, 8]) == [0, 2]
        assert regs.words[0x1C] == 7
        await bus.wait(1000)

    asyncio.run(run())
    assert bus.requests == 5


def test_serial_bus_splits_long_bursts_and_reads_in_pieces():
    class Memory:
        def read(self, address):
            return address * 3 & 0xFFFFFFFF, 0

        def write(self, address, data, strb):
            return 0

    port = FakePort(Memory())
    bus = SerialBus(port)
    got = asyncio.run(bus.read_burst(0x400000, 600))
    assert got == [((0x400000 + 4 * i) * 3 & 0xFFFFFFFF, 0) for i in range(600)]
    assert bus.requests == 3  # 256 + 256 + 88 words
    assert max(port.reads) == READ_PIECE
    assert asyncio.run(bus.write_burst(0, range(300))) == [0] * 300 and bus.requests == 5


def test_serial_bus_timeout_is_one_clear_line():
    bus = SerialBus(FakePort(Regs(), mute=True))
    with pytest.raises(TimeoutError, match=r"^no reply from the board: 0 of 6 bytes to a 'R' request") as e:
        asyncio.run(bus.read(0x10))
    assert "\n" not in str(e.value)


def test_serial_bus_reports_a_timed_out_request():
    """The board's '?' 'T' (the model's reply to a request cut off) becomes a ProtocolError."""
    port = FakePort(Regs())
    port.model.feed([0x57, 0, 0, PAUSE])
    bus = SerialBus(port)
    with pytest.raises(P.ProtocolError, match=r"timed out on the board"):
        asyncio.run(bus.read(0x10))
