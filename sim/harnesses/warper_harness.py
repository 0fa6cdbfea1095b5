"""A MyHDL bench harness around the coordinate warper: consumer, enable pattern, recorder and protocol checks.

The full-frame checks need 4 x width x height clocks per frame (1.2 M at 640x480); Python on every clock
would dominate. This harness, converted and simulated together with the warper, does the per-clock
work in the HDL:

* **consumer**: ``read_ack`` from a 32-bit LFSR: with probability ``ack_p / 256`` per clock (256: at
  once) while a pair is offered; ``ack_reg`` = 0 acknowledges combinationally (in the clock ``valid``
  rises), 1 as a registered one-clock pulse (the thesis's FAI); ``burst`` adds long stretches of no
  acknowledgement (200..2247 clocks) between stretches of acknowledging (100..1123 clocks);
* **enable**: the warper's clock enable, high with probability ``en_p / 256`` per clock (a second LFSR);
* **recorder**: every taken pair (valid, read_ack and enable high) is shifted, as the packed word of
  :func:`eyestereo.tools.models.coordinate_warper.pair_word`, into a ``batch``-pair register; when it is
  full, ``rec_data`` takes a copy and ``rec_strobe`` pulses, so Python wakes once per ``batch`` pairs;
  ``rec_shift``/``rec_count`` hold the pairs of the batch in progress (the newest at the top);
* **checks** (sticky bits of ``err``): bit 0, an output of the warper (pair, valid, busy, done) changed in
  a clock after one with ``enable`` low; bit 1, an offered pair disappeared or changed before it was
  taken;
* **counters**: ``cycle`` (clocks since reset), ``takes``, ``first_take``/``last_take`` (cycle numbers).

The harness is registered as the simulation-only catalogue top ``coordinate_warper_tb``
(:data:`eyestereo.hdl.flow.catalog.BENCH_TOPS`); its bench is :mod:`eyestereo.sim.benches.tb_coordinate_warper`.
"""

from __future__ import annotations

from myhdl import ConcatSignal, ResetSignal, Signal, always, always_comb, always_seq, block, concat, intbv

from eyestereo.hdl.flow.catalog import BENCH_TOPS, POLY_DEFAULTS as _POLY_DEFAULTS, BlockSpec
from eyestereo.hdl.interfaces.coord_pair import CoordPair
from eyestereo.hdl.rectify.calibration import calibration_of, calibration_param
from eyestereo.hdl.rectify.coordinate_warper import coordinate_warper
from eyestereo.hdl.rectify.poly_unit import CoefPort
from eyestereo.tools.models import coordinate_warper as model
from eyestereo.tools.models import poly_unit as unit_model

NAME = "coordinate_warper_tb"


def pair_bits(cal, frac: int) -> int:
    return model.pair_word(cal, frac).width


@block
def lfsr32(clk, rst, seed, state):
    """A Fibonacci LFSR (x^32 + x^30 + x^26 + x^25 + 1, maximal length) advancing every clock, loaded
    with ``seed | 1`` during reset."""

    @always(clk.posedge)
    def step():
        if rst:
            state.next = seed | 1
        else:
            state.next = concat(state[31:0], state[31] ^ state[29] ^ state[25] ^ state[24])

    return step


@block
def coordinate_warper_tb(clk, rst, start, busy, done, ack_p, ack_reg, burst, en_p, seed, rec_strobe, rec_data,
                         rec_shift, rec_count, err, cycle, takes, first_take, last_take, coef=None, *,
                         quantizers=None, frac: int | None = unit_model.DEFAULT_FRAC, source_width=None,
                         source_height=None, batch: int = 16):
    """The warper between an LFSR-driven consumer and enable, with a batching recorder (module docstring)."""
    cal = calibration_param(quantizers, source_width, source_height)
    frac = unit_model.resolve_frac(cal, frac)
    coord = CoordPair(cal.source_width, cal.source_height, frac)
    enable = Signal(bool(0))
    dut = coordinate_warper(clk, rst, start, enable, busy, done, coord, coef, quantizers=cal, frac=frac)

    pw = pair_bits(cal, frac)
    width = batch * pw
    la, le = Signal(intbv(0)[32:]), Signal(intbv(0)[32:])
    seed_e = Signal(intbv(0)[32:])
    rng_a = lfsr32(clk, rst, seed, la)
    rng_e = lfsr32(clk, rst, seed_e, le)

    go = Signal(bool(0))
    ack_r = Signal(bool(0))
    phase_on = Signal(bool(1))
    bcnt = Signal(intbv(0)[16:])
    take = Signal(bool(0))
    word = ConcatSignal(coord.eof, coord.eol, coord.oor_r, coord.oor_l, coord.yr, coord.xr, coord.yl, coord.xl)
    outs = ConcatSignal(done, busy, coord.valid, word)
    snap = Signal(intbv(0)[len(outs):])
    word_d = Signal(intbv(0)[pw:])
    en_d = Signal(bool(1))
    pend = Signal(bool(0))
    count = Signal(intbv(0, min=0, max=batch))
    shifted = Signal(intbv(0)[width:])
    started = Signal(bool(0))
    assert len(word) == pw

    @always_comb
    def seeds():
        seed_e.next = seed ^ 0x5DEECE66

    @always_comb
    def consumer():
        enable.next = le[8:0] < en_p
        go.next = phase_on and la[8:0] < ack_p
        if ack_reg:
            coord.read_ack.next = ack_r
        else:
            coord.read_ack.next = coord.valid and go

    @always_comb
    def taking():
        take.next = enable and coord.valid and coord.read_ack
        shifted.next = concat(word, rec_shift[width:pw])

    @always_seq(clk.posedge, reset=rst)
    def state():
        ack_r.next = coord.valid and go and not ack_r
        # acknowledge bursts
        if burst:
            if bcnt == 0:
                phase_on.next = not phase_on
                if phase_on:
                    bcnt.next = 200 + la[27:16]
                else:
                    bcnt.next = 100 + la[26:16]
            else:
                bcnt.next = bcnt - 1
        # recorder
        rec_strobe.next = 0
        if take:
            rec_shift.next = shifted
            takes.next = takes + 1
            last_take.next = cycle
            if not started:
                first_take.next = cycle
                started.next = 1
            if count == batch - 1:
                count.next = 0
                rec_data.next = shifted
                rec_strobe.next = 1
            else:
                count.next = count + 1
        cycle.next = cycle + 1
        # checks
        snap.next = outs
        en_d.next = enable
        pend.next = coord.valid and not take
        word_d.next = word
        if not en_d and outs != snap:
            err.next = err | 1
        if pend and (not coord.valid or word != word_d):
            err.next = err | 2

    @always_comb
    def counting():
        rec_count.next = count

    return dut, rng_a, rng_e, seeds, consumer, taking, state, counting


def _build(p):
    cal = calibration_of(p)
    pw = pair_bits(cal, unit_model.resolve_frac(cal, p["frac"]))
    b = p["batch"]
    if b < 2:
        raise ValueError(f"parameter batch must be at least 2, got {b}")
    ports = dict(clk=Signal(bool(0)), rst=ResetSignal(0, active=1, isasync=False), start=Signal(bool(0)),
                 busy=Signal(bool(0)), done=Signal(bool(0)), ack_p=Signal(intbv(0)[9:]),
                 ack_reg=Signal(bool(0)), burst=Signal(bool(0)), en_p=Signal(intbv(0)[9:]),
                 seed=Signal(intbv(0)[32:]), rec_strobe=Signal(bool(0)), rec_data=Signal(intbv(0)[b * pw:]),
                 rec_shift=Signal(intbv(0)[b * pw:]), rec_count=Signal(intbv(0, min=0, max=b)),
                 err=Signal(intbv(0)[2:]), cycle=Signal(intbv(0)[32:]), takes=Signal(intbv(0)[32:]),
                 first_take=Signal(intbv(0)[32:]), last_take=Signal(intbv(0)[32:]))
    if p["coefficients"] == "register":
        ports["coef"] = CoefPort(unit_model.coef_data_bits(cal.formats))
    return ports


SPEC = BlockSpec(NAME, "bench harness: coordinate_warper with an LFSR consumer and a batching recorder",
                 coordinate_warper_tb, dict(_POLY_DEFAULTS, batch=16),
                 hw_params=("quantizers", "frac", "source_width", "source_height", "batch"), build=_build)
BENCH_TOPS[NAME] = SPEC
