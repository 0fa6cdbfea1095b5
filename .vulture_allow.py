# Vulture's whitelist (make lint): names that vulture reports as unused but that are used, by name, from
# places vulture cannot see. One line per false positive; the comment names who uses it. Not imported by
# anything; vulture reads it as one of its paths (pyproject.toml, [tool.vulture]).
# ruff: noqa

# Python module hooks (PEP 562): `from eyestereo.hdl import harris_mono` loads the block on first use
__getattr__  # hdl/__init__.py: called by Python for a name the module does not define yet
__dir__  # hdl/__init__.py: called by dir() and tab completion, lists the lazily loaded exports

# hdl/common/callinfo.py: the shallow stand-ins take inspect.stack()'s and getouterframes()'s arguments
context  # MyHDL calls inspect.stack(context) / getouterframes(frame, context); the depth is DEPTH regardless
uninstall  # called by name in tests/hdl/test_callinfo.py's child script (a string run with python -c)

# Bundle widths named by string in MEMBERS (hdl/interfaces/bundle.py reads them with getattr)
_.tdata_bits  # hdl/interfaces/axis.py: Member("tdata", "tdata_bits", ...)
_.x_bits  # hdl/interfaces/coord_pair.py: Member("xl", "x_bits", ...)
_.y_bits  # hdl/interfaces/coord_pair.py: Member("yl", "y_bits", ...)
_.be_bits  # hdl/interfaces/sram_bus.py: Member("bw_n", "be_bits", ...), Member("be", "be_bits", ...)

# Functions run by name in a child process
run_vhdl  # sim/apps/cli_rectify.py: run_job("eyestereo.sim.apps.cli_rectify:run_vhdl", ...)

# cocotb agents keep the handle of the coroutine they start (cocotb's scheduler runs it; the handle is
# there to inspect or kill it from a bench or a debugger)
_._task  # sim/lib/axil.py, sim/lib/sram_model.py, sim/lib/stream.py
_._tasks  # sim/lib/stream.py: the monitor's coroutine and its watchers

# pytest finds these by name
pytestmark  # tests/*: the module's markers (sim, synth), read by pytest
pytest_collection_modifyitems  # tests/conftest.py: pytest's collection hook
pytest_configure  # tests/conftest.py: pytest's configuration hook (registers the run-order plugin)

# tools/sram.py's SramStats counters: only incremented in the library; the benches read them all at once
# through vars(chip.stats) (sim/benches/tb_sram_subsystem.py: the bus figures of the report)
_.deselects  # SramStats.deselects
_.sram_drive_cycles  # SramStats.sram_drive_cycles
_.fpga_drive_cycles  # SramStats.fpga_drive_cycles
_.idle_bus_cycles  # SramStats.idle_bus_cycles

# cocotb benches made by sim/lib/model_bench.py: model_bench() returns a cocotb.test that the bench module
# binds to a name; cocotb finds it among the module's attributes and names it by __name__, __qualname__
# and __module__ (set by model_bench so that the test reads as the bench's own)
_.__qualname__  # sim/lib/model_bench.py: the test's and the bench class's names
_.__module__  # sim/lib/model_bench.py: the bench module the test belongs to
line_delay_frames  # sim/benches/tb_line_delay.py
harris_window_frames  # sim/benches/tb_harris_window.py
# the benches' classes, named by string "module:class" in tests/hdl/test_recovery.py's cases
LineDelayTB  # sim/benches/tb_line_delay.py
HarrisWindowTB  # sim/benches/tb_harris_window.py

# public result records of the FFC toolbox (tools/rectify/ffc.py): fields for the user's reports and the
# CLI's JSON (dataclasses.asdict), read by name outside the library
_.description  # ErrorMeasure.description: the metric's one-line text for reports
_.coarse_error  # PolyFFC.coarse_error: the error of the coarse search, before the greedy refinement
_.coarse_trace  # PolyFFC.coarse_trace: (bits, error) of each coarse step

# MyHDL user-defined code (sim/harnesses/frontend_harness.py): the templates name the block's locals, MyHDL reads the
# attributes by name when it converts
file_name  # camera_player's $file_name in its verilog_code / vhdl_code templates
_.verilog_code  # the user-defined Verilog of camera_player and sram_part
_.vhdl_code  # the user-defined VHDL of camera_player and sram_part

# sim/lib/sccb.py: SccbRules's fields are read by name (SccbRules.ps(name), the rule names in its messages)
_.t_cyc  # SccbSlave._rise: "t_cyc"
_.t_low  # SccbSlave._rise: "t_low"
_.t_high  # SccbSlave._fall: "t_high"
_.t_su_sta  # SccbSlave._start: "t_su_sta"
_.t_hd_sta  # SccbSlave._fall: "t_hd_sta"
_.t_su_dat  # SccbSlave._rise: "t_su_dat"
_.t_su_sto  # SccbSlave._stop: "t_su_sto"
_.t_buf  # SccbSlave._start: "t_buf"
_.t_aa  # SccbBus._drive: "t_aa"
_.reset_wait  # SccbSlave._start: "reset_wait"

# sim/benches/tb_board.py: the SDRAM model reads its pins by name (getattr(dut, f"{prefix}_{field}"))
_.pins_dq_o  # sim/benches/tb_board.py SdramPins: read by SdramModel as dut.pins_dq_o
_.pins_dq_oe  # sim/benches/tb_board.py SdramPins: read by SdramModel as dut.pins_dq_oe
_.pins_dq_i  # sim/benches/tb_board.py SdramPins: written by SdramModel as dut.pins_dq_i

# hdl/flow/bitstream.py: the conversion runs in a child Python (a fixed string-hash seed), which calls it by name
convert_top  # hdl/flow/bitstream.py: called by the child's code string (_CHILD)
