"""hdl/system/disparity_writer.py in MyHDL's simulator: frames into the two buffers through a memory port that
is not always ready, the register bank's reads through the same port, the host's take and release, a reset
token abandoning a frame, and the sticky ``lost`` flag of a FIFO that overflows. (The front end's bench runs its
VHDL and Verilog with the whole system: tests/hdl/test_stereo_frontend.py.)"""

import random

from myhdl import ResetSignal, Signal, Simulation, StopSimulation, always, delay, instance, intbv

from eyestereo.hdl.interfaces.sram_bus import HostPort
from eyestereo.hdl.interfaces.stream import ImageStream
from eyestereo.hdl.system.disparity_writer import disparity_writer

W, H = 5, 3
BASE0, BASE1 = 1000, 2000


def run(script, *, depth=16, ready=0.6, seed=1):
    """Run the writer with ``script(put, wait, host)`` driving it; returns the memory's words, the writes in
    order, the bank's read answers and the outputs sampled at the end."""
    clk, rst = Signal(bool(0)), ResetSignal(1, active=1, isasync=False)
    sink, bank, mem = ImageStream(16), HostPort(), HostPort()
    want, release, held, avail, buf, lost = (Signal(bool(0)) for _ in range(6))
    frames = Signal(intbv(0)[16:])
    dut = disparity_writer(clk, rst, sink, bank, mem, want, release, held, avail, buf, frames, lost, base0=BASE0,
                           base1=BASE1, width=W, height=H, depth=depth)
    rng = random.Random(seed)
    memory, writes, answers, out = {}, [], [], {}
    pending = []  # read answers in flight: (clocks left, data)

    @always(delay(5))
    def clock():
        clk.next = not clk

    @instance
    def memory_side():
        # the arbiter's host port as the bank sees it: ready from a register, reads answered 3 clocks later
        while True:
            mem.req_ready.next = rng.random() < ready
            yield clk.posedge
            if mem.req_valid and mem.req_ready:
                if mem.req_we:
                    memory[int(mem.req_addr)] = int(mem.req_wdata)
                    writes.append(int(mem.req_addr))
                else:
                    pending.append([3, memory.get(int(mem.req_addr), 0)])
            mem.rsp_valid.next = False
            if pending:
                pending[:] = [[n - 1, d] for n, d in pending]
                if pending[0][0] <= 0:
                    mem.rsp_valid.next = True
                    mem.rsp_data.next = pending.pop(0)[1]

    @instance
    def bank_answers():
        while True:
            yield clk.posedge
            if bank.rsp_valid:
                answers.append(int(bank.rsp_data))

    def put(code, eol=False, eof=False):
        sink.valid.next, sink.data.next, sink.eol.next, sink.eof.next = True, code, eol, eof
        yield clk.posedge
        sink.valid.next = False

    def frame(codes, gap=0):
        for i, c in enumerate(codes):
            yield from put(c, eol=(i + 1) % W == 0, eof=i + 1 == W * H)
            for _ in range(gap):
                yield clk.posedge

    def wait(n):
        for _ in range(n):
            yield clk.posedge

    def host_read(addr):
        bank.req_valid.next, bank.req_we.next, bank.req_addr.next = True, False, addr
        while True:
            yield clk.posedge
            if bank.req_ready:
                break
        bank.req_valid.next = False

    ctl = dict(want=want, release=release, held=held, avail=avail, buf=buf, frames=frames, lost=lost,
               frame=frame, put=put, wait=wait, read=host_read, out=out)

    @instance
    def main():
        yield wait(3)
        rst.next = 0
        yield clk.posedge
        yield from script(ctl)
        out.update(held=bool(held), avail=bool(avail), buf=int(buf), frames=int(frames), lost=bool(lost))
        raise StopSimulation

    Simulation(dut, clock, memory_side, bank_answers, main).run(quiet=1)
    return memory, writes, answers, out


def codes(k):
    return [(k * 100 + i) & 0xFFFF for i in range(W * H)]


def test_frames_alternate_buffers_and_the_host_takes_the_newest():
    seen = {}

    def script(c):
        yield from c["frame"](codes(1))
        yield from c["wait"](60)
        seen["after_one"] = (bool(c["avail"]), int(c["frames"]))
        yield from c["frame"](codes(2), gap=2)
        yield from c["wait"](60)
        c["want"].next = True
        yield from c["wait"](3)
        seen["taken"] = (bool(c["held"]), int(c["buf"]))
        c["want"].next = False
        # the register bank reads a word of the buffer held while the next frame is written
        yield from c["read"](BASE0 + 7)
        yield from c["frame"](codes(3))
        yield from c["wait"](60)
        c["release"].next = True
        yield from c["wait"](1)
        c["release"].next = False
        yield from c["wait"](2)

    memory, writes, answers, out = run(script)
    assert seen["after_one"] == (True, 1)
    # both buffers FREE: the first frame takes buffer 1 (not the newest, which starts as 0), the second buffer 0
    assert seen["taken"] == (True, 0)  # the newest: frame 2
    assert [memory[BASE0 + i] for i in range(W * H)] == codes(2)
    # frame 3 cannot go to buffer 0 (held): buffer 1, over frame 1
    assert [memory[BASE1 + i] for i in range(W * H)] == codes(3)
    assert writes == list(range(BASE1, BASE1 + 15)) + list(range(BASE0, BASE0 + 15)) + list(range(BASE1, BASE1 + 15))
    assert answers == [codes(2)[7]]
    assert out == dict(held=False, avail=True, buf=0, frames=3, lost=False)


def test_a_token_abandons_the_frame_and_the_next_one_starts_over():
    def script(c):
        for v in codes(5)[:8]:
            yield from c["put"](v)
        yield from c["put"](0, eol=False, eof=True)  # reset token
        yield from c["frame"](codes(6))
        yield from c["wait"](80)

    memory, writes, _, out = run(script, ready=1.0)
    assert out["frames"] == 1 and out["avail"] and not out["lost"]
    # the cut frame's words went to a buffer that the double buffer freed again; the next frame took a buffer
    # from its first word on, and only it was published
    done = BASE0 if [memory.get(BASE0 + i) for i in range(W * H)] == codes(6) else BASE1
    assert [memory[done + i] for i in range(W * H)] == codes(6)
    assert writes[-15:] == list(range(done, done + 15))


def test_a_full_fifo_loses_codes_and_says_so():
    def script(c):
        yield from c["frame"](codes(7))  # 15 codes at one per clock into 16 entries, the port hardly ever ready
        yield from c["frame"](codes(8))
        yield from c["wait"](20)

    _, _, _, out = run(script, ready=0.02, depth=16)
    assert out["lost"]
