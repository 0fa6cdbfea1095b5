"""GHDL regression of the register bank through the AXI4-Lite bus model, checked against the register table."""

import shutil

import pytest

from eyestereo.sim.lib.runner import run_bench

needs_ghdl = pytest.mark.skipif(shutil.which("ghdl") is None, reason="GHDL not installed")


@needs_ghdl
@pytest.mark.sim
def test_register_bank_against_table(request):
    rep = run_bench("register_bank", "tb_register_bank", dict(seed=3, pause=0.3), name=request.node.name,
                    params=dict(width=64, height=48))
    assert rep["counts"]["ar"] > 300 and rep["gaps"] > 100
    # the bench counts the SRAM window's host port requests exactly (a write of the upper bytes alone makes none):
    # at least its 16 reads
    assert rep["host_requests"] >= 16


# ---- elaboration: ports checked, port list from the table (no simulator needed for these) -----------
from myhdl import ResetSignal, Signal, intbv  # noqa: E402

from eyestereo.hdl.interfaces.axil import AxiLite  # noqa: E402
from eyestereo.hdl.flow.catalog import BLOCKS  # noqa: E402
from eyestereo.hdl.system.register_bank import RegisterPorts, register_bank  # noqa: E402
from eyestereo.hdl.interfaces.sram_bus import HostPort, StatPort  # noqa: E402
from eyestereo.tools.regmap import REGMAP  # noqa: E402


def _ports(**over):
    p = BLOCKS["register_bank"].ports()[0]
    p.update(over)
    return p


@pytest.mark.parametrize("over,match", [
    (dict(bus=AxiLite(32)), r"port bus must have 23 address bits"),
    (dict(bus=None), r"port bus must be an AxiLite.*got None"),
    (dict(regs=StatPort()), r"port regs must be a RegisterPorts"),
    (dict(arb=StatPort(5, 16)), r"port arb needs 5 address bits and 32 data bits, got 5 and 16"),
    (dict(fcount=StatPort()), r"port fcount needs 5 address bits and 16 data bits"),
    (dict(host=HostPort(addr_bits=16)), r"port host needs 20 address bits"),
    (dict(host=1), r"port host must be a HostPort"),
    (dict(rst=Signal(bool(0))), r"port rst must be a ResetSignal"),
    (dict(clk=ResetSignal(0, active=1, isasync=False)), r"port clk must be the clock"),
])
def test_bad_ports_are_refused(over, match):
    with pytest.raises(ValueError, match=rf"^register_bank: {match}"):
        register_bank(*_ports(**over).values())


def test_a_wrong_field_port_is_refused():
    regs = RegisterPorts()
    regs.k_left = Signal(intbv(0)[9:])
    with pytest.raises(ValueError, match=r"^register_bank: port regs: field k_left must be a 8-bit Signal"):
        register_bank(*_ports(regs=regs).values())


@pytest.mark.parametrize("kw,match", [(dict(width=1), "width=1 is too small"),
                                      (dict(height=4097), "height=4097 is too large"),
                                      (dict(width=8.0), "width must be an integer")])
def test_bad_parameters_are_refused(kw, match):
    with pytest.raises(ValueError, match=rf"^register_bank: parameter {match}"):
        register_bank(*_ports().values(), **kw)


@needs_ghdl
def test_vhdl_ports_follow_the_table(tmp_path):
    from eyestereo.hdl.flow.convert import convert, vhdl_ports

    files = convert("register_bank", tmp_path)
    ports = {p["name"]: p for p in vhdl_ports(files[-1])}
    for r in REGMAP:
        for f in r.fields:
            if r.kind in ("rw", "pulse"):
                assert ports[f"regs_{f.name}"]["dir"] == "out", f.name
            elif r.kind == "status":
                assert ports[f"regs_{f.name}"]["dir"] == "in", f.name
        if r.kind == "array":
            assert ports[f"regs_{r.port}_data"]["type"] == "unsigned(19 downto 0)"
            assert ports[f"regs_{r.port}_addr"]["type"] == "unsigned(3 downto 0)"
    assert ports["bus_awaddr"]["type"] == "unsigned(22 downto 0)" and ports["bus_rdata"]["dir"] == "out"
    assert ports["arb_addr"]["dir"] == "out" and ports["arb_data"]["dir"] == "in"
    assert ports["host_req_valid"]["dir"] == "out" and ports["host_rsp_data"]["dir"] == "in"
    # (tests/hdl/test_vhdl.py analyses it under both standards with every catalogue block)


@pytest.mark.sim
@pytest.mark.skipif(shutil.which("iverilog") is None, reason="Icarus Verilog not installed")
def test_register_bank_verilog_on_icarus(request):
    """MyHDL's Verilog back end can differ from its VHDL one: the same bench on the Verilog, in Icarus."""
    from eyestereo.sim.lib.sram_runner import run_sram_bench

    rep = run_sram_bench("register_bank", "tb_register_bank",
                         dict(seed=5, pause=0.2, salts=1, full=False, rw_writes=15), name=request.node.name,
                         params=dict(width=64, height=48), sim="icarus")
    assert rep["counts"]["ar"] > 150


@needs_ghdl
@pytest.mark.sim
@pytest.mark.skipif(shutil.which("iverilog") is None, reason="Icarus Verilog not installed")
def test_register_bank_netlist(request):
    """The netlist make synth measures (GHDL's synthesis of the VHDL) passes the same bench, in Icarus."""
    from eyestereo.sim.lib.netlist import run_netlist_bench

    rep = run_netlist_bench("register_bank", "tb_register_bank", dict(seed=6, pause=0.2, salts=1, full=False,
                                                                         rw_writes=15), name=request.node.name)
    assert rep["counts"]["ar"] > 150


@needs_ghdl
@pytest.mark.sim
def test_host_driver_on_the_sram_subsystem(request):
    """The bank wired to the real arbiter and controller (sim/harnesses/host_harness.py): the host reads a camera
    frame and the arbiter's counters through the bus."""
    import eyestereo.sim.harnesses.host_harness  # noqa: F401  (registers the bench top)

    rep = run_bench("host_system_tb", "tb_host_system", dict(seed=2, pause=0.2), name=request.node.name,
                    params=dict(width=16, height=4, feature_words=64))
    assert rep["arb"]["moved_cam0"] == 64 and rep["host_moves"] == 24 + 64


# ---- frame_handshake: the host's frame-handshake fields wired to the arbiter (system top and bench top) ---
def test_frame_handshake_fields():
    """The fields docs/registers.md ("Connections") wires to FrameControl, and which way each goes."""
    from eyestereo.hdl.system.frame_handshake import HANDSHAKE

    assert dict(HANDSHAKE) == {"rect_want": True, "feat_want": True, "rect_release": True, "feat_release": True,
                               "avail": False, "rect_held": False, "feat_held": False, "rect_buf": False,
                               "feat_buf": False}


def test_frame_handshake_wires_each_field():
    """In MyHDL's simulator: a value on each bank output appears on the arbiter's member, a value on each
    arbiter output on the bank's status field; nothing else moves."""
    from myhdl import Simulation, delay, instance

    from eyestereo.hdl.memory.frame_buffers import FrameControl
    from eyestereo.hdl.system.frame_handshake import frame_handshake

    regs, ctl = RegisterPorts(), FrameControl()
    dut = frame_handshake(regs, ctl)
    to_arbiter = ("rect_want", "feat_want", "rect_release", "feat_release")
    from_arbiter = {"avail": 0b1010, "rect_held": 1, "feat_held": 1, "rect_buf": 1, "feat_buf": 1}
    seen = {}

    @instance
    def stim():
        for name in to_arbiter:
            getattr(regs, name).next = 1
            yield delay(1)
            seen[name] = [int(getattr(ctl, n)) for n in to_arbiter]
            getattr(regs, name).next = 0
            yield delay(1)
        for name, value in from_arbiter.items():
            getattr(ctl, name).next = value
            yield delay(1)
            seen[name] = int(getattr(regs, name))
        seen["cam"] = (int(ctl.cam_want), int(ctl.cam_release))

    Simulation(dut, stim).run(quiet=1)
    for i, name in enumerate(to_arbiter):
        assert seen[name] == [int(j == i) for j in range(4)], name
    for name, value in from_arbiter.items():
        assert seen[name] == value, name
    assert seen["cam"] == (0, 0)


def test_frame_handshake_refuses_other_bundles():
    from eyestereo.hdl.memory.frame_buffers import FrameControl
    from eyestereo.hdl.system.frame_handshake import frame_handshake

    with pytest.raises(ValueError, match=r"^frame_handshake: port ctl must be a FrameControl"):
        frame_handshake(RegisterPorts(), HostPort())
    with pytest.raises(ValueError, match=r"^frame_handshake: port regs must be a RegisterPorts"):
        frame_handshake(FrameControl(), FrameControl())
