"""The SDRAM parts (tools/sdram.py): datasheet figures as clocks, the address map, the mode register, bad
parameters, and the part model's rules on hand-written pin sequences (one that keeps a rule, one that
breaks it). Expected values are worked out by hand from the datasheets' figures."""

import pytest

from eyestereo.tools.sdram import PARTS, Pins, SdramChip, SdramPart, join, mode_register, part, power_up_word, split

AS7 = "AS4C32M16SB-7"


# --- clocks ------------------------------------------------------------------------------------------
def test_as4c32m16sb_7_at_100_mhz():
    ck = part(AS7).clocks(100)
    # 21/10 -> 3, 21 -> 3, 42 -> 5, 63 -> 7, 14 -> 2, 14 -> 2, 63 -> 7; 7812.5/10 -> 781 (down); 200 us
    assert (ck.rcd, ck.rp, ck.ras, ck.rc, ck.rrd, ck.wr, ck.rfc) == (3, 3, 5, 7, 2, 2, 7)
    assert (ck.refi, ck.powerup, ck.mrd, ck.ras_max) == (781, 20_000, 2, 12_000)


def test_as4c32m16sb_7_at_133_mhz():
    ck = part(AS7).clocks(133)  # 7.5188 ns
    # 21/7.52 = 2.79 -> 3, 42/7.52 = 5.59 -> 6, 63/7.52 = 8.38 -> 9, 14/7.52 = 1.86 -> 2, 7812.5/7.52 = 1039.06 -> 1039
    assert (ck.rcd, ck.rp, ck.ras, ck.rc, ck.rrd, ck.wr, ck.rfc) == (3, 3, 6, 9, 2, 2, 9)
    assert (ck.refi, ck.powerup) == (1039, 26_600)


def test_mt48lc16m16a2_7e_at_100_mhz():
    ck = part("MT48LC16M16A2-7E").clocks(100)
    # tRCD 15, tRP 15, tRAS 37, tRC 60, tRRD 14, tWR 14, tRFC 66; power-up 100 us
    assert (ck.rcd, ck.rp, ck.ras, ck.rc, ck.rrd, ck.wr, ck.rfc, ck.powerup) == (2, 2, 4, 6, 2, 2, 7, 10_000)


def test_exact_multiples_round_to_themselves():
    ck = part("AS4C32M16SB-6").clocks(50)  # 20 ns: tRC 60 -> 3 exactly, tRCD 18 -> 1
    assert (ck.rc, ck.rcd, ck.rrd) == (3, 1, 1)


def test_max_clock_per_cas_latency():
    p = part(AS7)
    assert p.max_mhz(2) == pytest.approx(100.0)
    assert p.max_mhz(3) == pytest.approx(142.857, abs=1e-3)
    assert part("AS4C32M16SB-6").max_mhz(3) == pytest.approx(166.667, abs=1e-3)


# --- geometry and address map ------------------------------------------------------------------------
def test_geometry():
    a, m = part(AS7), part("MT48LC16M16A2-75")
    assert (a.words, a.addr_bits, a.megabytes, a.a_bits, a.bank_bits) == (1 << 25, 25, 64.0, 13, 2)
    assert (m.words, m.addr_bits, m.megabytes, m.col_bits) == (1 << 24, 24, 32.0, 9)
    assert a.t_refi == 7812.5


def test_address_map_row_bank_column():
    p = part(AS7)
    assert split(p, 0) == (0, 0, 0)
    assert split(p, 1023) == (0, 0, 1023)
    assert split(p, 1024) == (1, 0, 0)       # the next row's worth of words: the next bank
    assert split(p, 4096) == (0, 1, 0)
    assert split(p, (1 << 25) - 1) == (3, 8191, 1023)
    assert join(p, 2, 5, 7) == (5 * 4 + 2) * 1024 + 7
    assert split(part("MT48LC16M16A2-7E"), 512) == (1, 0, 0)


def test_mode_register_words():
    assert mode_register(1, 2) == 0x020
    assert mode_register(8, 3) == 0x033
    assert mode_register("page", 3) == 0x037
    assert mode_register(4, 2, interleaved=True) == 0x02A
    assert mode_register(1, 3, single_write=True) == 0x230


def test_spec_round_trip():
    p = part("AS4C32M16SB-7:refresh_ms=8.192,powerup_us=1")
    assert p.t_refi == 1000.0 and p.powerup_us == 1.0 and p.t_rcd == 21.0
    assert part(p.spec) == p and p.name == p.spec == "AS4C32M16SB-7:refresh_ms=8.192,powerup_us=1.0"
    assert part(AS7).spec == AS7 and part(PARTS[AS7]) is PARTS[AS7]


# --- bad parameters -------------------------------------------------------------------------------------
@pytest.mark.parametrize("kw,why", [
    (dict(banks=3), "banks"), (dict(columns=1000), "columns"), (dict(t_rcd=-1.0), "t_rcd"),
    (dict(t_ras_max=40.0), "t_ras_max"), (dict(t_rc=30.0), "t_rc"), (dict(tck_cl3=12.0), "CAS latency 3"),
    (dict(init_refreshes=1), "init_refreshes"), (dict(refresh_ms=0.005), "tREFI"), (dict(data_bits=12), "data_bits"),
])
def test_bad_part_figures(kw, why):
    with pytest.raises(ValueError, match=why):
        SdramPart("X", **kw)


@pytest.mark.parametrize("spec,why", [
    ("NOPE", "unknown SDRAM part"), (f"{AS7}:foo=1", "field=value"), (f"{AS7}:t_rcd=abc", "must be a float"),
    (f"{AS7}:banks=2.5", "must be a int"), (f"{AS7}:t_rcd=-3", "positive"), (42, "a name from"),
])
def test_bad_part_specs(spec, why):
    with pytest.raises(ValueError, match=why):
        part(spec)


def test_bad_arguments():
    p = part(AS7)
    for bad in (lambda: p.clocks(0), lambda: p.clocks(True), lambda: split(p, -1), lambda: split(p, 1 << 25),
                lambda: join(p, 4, 0, 0), lambda: mode_register(3, 2), lambda: mode_register(1, 4),
                lambda: mode_register("page", 2, interleaved=True), lambda: p.max_mhz(1)):
        with pytest.raises(ValueError):
            bad()


# --- the part model's rules -------------------------------------------------------------------------------
NOP = dict(cs_n=1)
FAST = "AS4C32M16SB-7:powerup_us=0.1,refresh_ms=8.192"  # 10 clocks of power-up wait, tREFI 1 us


def cmd(name, ba=0, a=0, **kw):
    codes = dict(ACT=(0, 1, 1), READ=(1, 0, 1), WRITE=(1, 0, 0), PRE=(0, 1, 0), REF=(0, 0, 1), MRS=(0, 0, 0))
    r, c, w = codes[name]
    return dict(cs_n=0, ras_n=r, cas_n=c, we_n=w, ba=ba, a=a, **kw)


def init_seq(cl=2):
    """Edge -> pins of a correct power-up at 100 MHz (10 clocks wait; tRP 3, tRFC 7, tMRD 2 clocks)."""
    s = {11: cmd("PRE", a=1 << 10)}
    for k in range(8):
        s[14 + 7 * k] = cmd("REF")
    s[14 + 7 * 8] = cmd("MRS", a=mode_register(1, cl))  # edge 70; ready, commands from 72
    return s


def run(seq, *, last=None, period=10.0, cl=2, spec=FAST, record=False):
    chip = SdramChip(spec, period_ns=period, cas_latency=cl, record=record)
    out = {}
    for t in range(1, (last or max(seq)) + 1):
        out[t] = chip.edge(t, Pins(**{**NOP, **seq.get(t, {})}))
    return chip, out


def rules(chip):
    return [v.split(": ")[1] for v in chip.violations]


def test_good_sequence_writes_and_reads_back():
    s = init_seq()
    s[72] = cmd("ACT", ba=1, a=77)
    s[75] = cmd("WRITE", ba=1, a=5, dq_oe=1, dq_o=0xBEEF, dqm=0)      # tRCD 21 ns: 3 clocks
    s[76] = cmd("WRITE", ba=1, a=6, dq_oe=1, dq_o=0x1234, dqm=2)      # upper byte masked
    s[77] = cmd("READ", ba=1, a=5, dqm=0)
    s[78] = cmd("READ", ba=1, a=6, dqm=0)
    s[79] = dict(cs_n=1, dqm=0)
    s[80] = cmd("PRE", ba=1)                                          # tRAS 42 ns, tWR 14 ns
    chip, out = run(s, last=90)
    assert chip.violations == []
    a5, a6 = join(chip.part, 1, 77, 5), join(chip.part, 1, 77, 6)
    assert out[78] == (0xBEEF, 0xFFFF)                                 # CL 2: driven in cycle 77 + 1
    assert out[79] == ((power_up_word(a6) & 0xFF00) | 0x34, 0xFFFF)
    assert chip.word(a5) == 0xBEEF and chip.stats.ready_edge == 70
    assert chip.write_log == [] and chip.read_log == []               # not recorded unless asked


def test_access_logs_and_reads_in_flight():
    """``record``: every write (its edge, address and the word after it, masked bytes kept) and every read
    (the READ's edge and address), the benches' source for checking reads; ``pending`` names reads in flight."""
    s = init_seq()
    s[72] = cmd("ACT", ba=2, a=9)
    s[75] = cmd("WRITE", ba=2, a=3, dq_oe=1, dq_o=0xA5C3, dqm=1)      # lower byte masked
    s[77] = cmd("READ", ba=2, a=3, dqm=0)
    s[78] = cmd("READ", ba=2, a=4, dqm=0)
    chip, _ = run({k: v for k, v in s.items() if k <= 77}, record=True)
    a3, a4 = (9 * 4 + 2) * 1024 + 3, (9 * 4 + 2) * 1024 + 4
    assert not chip.idle and chip.pending().startswith("1 reads in flight")   # driven in cycle 78
    chip, _ = run(s, last=85, record=True)
    assert chip.violations == [] and chip.idle and chip.pending().startswith("0 reads")
    assert chip.write_log == [(75, a3, (power_up_word(a3) & 0x00FF) | 0xA500)]
    assert chip.read_log == [(77, a3), (78, a4)]


@pytest.mark.parametrize("change,rule", [
    ({75: None, 74: cmd("WRITE", ba=1, a=5, dq_oe=1, dq_o=1)}, "tRCD"),
    ({80: None, 76: cmd("PRE", ba=1)}, "tRAS"),
    ({73: cmd("ACT", ba=2, a=3)}, "tRRD"),
    ({73: cmd("ACT", ba=1, a=3)}, "bank state"),                  # the bank's row is open
    ({75: cmd("READ", ba=2, a=5)}, "bank state"),                 # no open row in bank 2
    ({77: None, 79: cmd("WRITE", ba=1, a=6, dq_oe=1, dq_o=1, dqm=0)}, "tWR"),  # PRE at 80: 10 ns after
    ({82: cmd("ACT", ba=1, a=9)}, "tRP"),                         # 2 clocks after PRECHARGE
    ({81: cmd("REF")}, "tRP"),
    ({5: cmd("PRE", a=1 << 10)}, "power-up"),                     # before the 100 ns wait
    ({70: None, 72: None, 75: None, 71: cmd("ACT", ba=1, a=77)}, "power-up"),  # ACTIVATE before the mode register
    ({79: dict(cs_n=1, dq_oe=1, dq_o=0)}, "data bus"),            # stray drive
    ({75: cmd("WRITE", ba=1, a=5, dq_oe=0)}, "data bus"),         # a write without its data
    ({79: cmd("WRITE", ba=1, a=7, dq_oe=1, dq_o=1, dqm=0)}, "data bus"),  # contention with the read of 77
    ({71: cmd("REF")}, "tMRD"),
    ({77: cmd("READ", ba=1, a=5 | 1 << 10, dqm=0)}, "bank state"),  # auto precharge
])
def test_broken_rules(change, rule):
    s = init_seq()
    s.update({72: cmd("ACT", ba=1, a=77), 75: cmd("WRITE", ba=1, a=5, dq_oe=1, dq_o=0xBEEF, dqm=0),
              77: cmd("READ", ba=1, a=5, dqm=0), 80: cmd("PRE", ba=1)})
    for t, pins in change.items():
        if pins is None:
            s.pop(t)
        else:
            s[t] = pins
    chip, _ = run(s, last=95)
    assert rule in rules(chip), chip.violations


def test_turnaround_after_read():
    s = init_seq()
    s.update({72: cmd("ACT", ba=1, a=77), 75: cmd("READ", ba=1, a=5, dqm=0),
              78: cmd("WRITE", ba=1, a=6, dq_oe=1, dq_o=1, dqm=0)})  # read drives cycle 76, write data in 77
    chip, _ = run(s, last=80)
    assert rules(chip) == ["data bus"] and "turnaround" in chip.violations[0]
    s[78] = None
    s[79] = cmd("WRITE", ba=1, a=6, dq_oe=1, dq_o=1, dqm=0)  # one idle cycle (77): fine
    chip, _ = run({k: v for k, v in s.items() if v}, last=80)
    assert chip.violations == []


def test_read_dqm_masks_the_part_cl3():
    s = init_seq(cl=3)
    s.update({72: cmd("ACT", ba=0, a=1), 75: cmd("READ", ba=0, a=2, dqm=3), 76: dict(cs_n=1, dqm=1)})
    chip, out = run(s, last=80, cl=3)
    assert chip.violations == []
    # CL 3: driven in cycle 77; the dqm of edge 76 (two edges before the FPGA samples it at 78) masks byte 0
    assert out[77] == (power_up_word(join(chip.part, 0, 1, 2)) & 0xFF00, 0xFF00)


def test_mode_register_cas_latency_checked():
    chip, _ = run(init_seq(cl=3), last=72, cl=2)
    assert rules(chip) == ["mode register"]


def test_refresh_on_time_late_and_postponed():
    s = init_seq()
    for k in range(1, 6):               # tREFI = 100 clocks from edge 70: due at 170, 270, ...; done 10 later
        s[70 + 100 * k + 10] = cmd("REF")
    chip, _ = run(s, last=600)
    chip.finish(600)
    assert chip.violations == [] and chip.stats.refreshes == 5 and chip.stats.late_refreshes == 0
    assert chip.stats.max_owed == 1
    s = init_seq()
    s[70 + 250] = cmd("REF")            # the first due at 170, still owed at 270: late (the second, due at
    chip, _ = run(s, last=360)          # 270, is owed until 370)
    assert chip.stats.late_refreshes == 1 and chip.violations == []
    chip, _ = run(init_seq(), last=70 + 1000)  # none for 10 x tREFI: too long, more than 8 owed
    chip.finish(70 + 1000)
    assert "refresh" in rules(chip) and chip.stats.max_owed == 10


def test_ras_max():
    s = init_seq()
    s[72] = cmd("ACT", ba=0, a=1)
    spec = "AS4C32M16SB-7:powerup_us=0.1,refresh_ms=8.192,t_ras_max=500"
    chip, _ = run(s, last=130, spec=spec)
    chip.finish(130)
    assert "tRAS max" in rules(chip)
