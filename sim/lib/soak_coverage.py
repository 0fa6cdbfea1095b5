"""Functional coverage of the fault soak (issue 25), with cocotb-coverage: the plan, the sampling, the merged report.

The plan (every bin below is meant to be hit; :data:`HOLE_REASONS` says why a bin the soak cannot reach is not):

* ``soak.run.size``, ``soak.run.clocks`` and their cross: the frame sizes of the runs (:data:`SIZES`) and the ratio
  of the two cameras' clocks (:func:`clock_ratio`: equal, near (under 1 % apart), far (at least 10 % apart));
* ``soak.fault.kind`` x ``soak.fault.mode``: every fault kind of :data:`eyestereo.sim.lib.soak.FAULTS` injected in
  either operating mode (a camera fault counts in the mode the system was in when its frame began);
* ``soak.stall.*``: the stall patterns by length: the host's pauses (frames), the PCLK stops (PCLK periods), the late
  starts (frames);
* ``soak.register.access``: every register of the map and each access its kind allows (reads of const, status,
  window and memory registers; reads and writes of rw and array registers; writes of pulse registers), as the host
  made them on the bus;
* ``soak.fifo.level``: the highest fill of each camera FIFO per frame read (the harness's FIFO watch), in bins up to
  full.

Each run exports its database (:func:`export`); :func:`merge` merges the runs' files with cocotb-coverage's
``merge_coverage`` and :func:`report` turns the merged file into Markdown: per coverpoint the bins hit, and every
hole with its reason.
"""

from __future__ import annotations

from pathlib import Path

from cocotb_coverage.coverage import CoverCross, CoverPoint, coverage_db, merge_coverage

from eyestereo.sim.lib.soak import FAULTS
from eyestereo.tools.regmap import REGMAP

SIZES = ("48x32", "96x72", "352x288")
RATIOS = ("equal", "near", "far")
MODES = ("sequential", "overlapped")
PAUSE_BINS = ((1.0, 1.5), (1.5, 2.5), (2.5, 3.01))
STOP_BINS = ((2, 10), (10, 500), (500, 2001))
LATE_BINS = ((1.0, 1.5), (1.5, 2.01))
#: Camera FIFO fill bins (the front end's camera FIFOs hold 32 words): (lowest, highest) fill.
FIFO_BINS = ((0, 1), (2, 3), (4, 7), (8, 15), (16, 23), (24, 31), (32, 32))
OPS = {"const": ("read",), "status": ("read",), "window": ("read",), "memory": ("read", "write"),
       "rw": ("read", "write"), "array": ("read", "write"), "pulse": ("write",)}
REG_BINS = tuple((r.name, op) for r in REGMAP for op in OPS[r.kind])
#: Bins the soak does not reach, and why (the report names them with these reasons).
HOLE_REASONS = {
    ("SRAM", "write"): "the host writes no SRAM word in the soak (the host port's writes: tb_register_bank)",
    ("DENSE", "read"): "the dense option is not built into the soak's top (its own bench: tb_stereo_frontend --dense)",
    ("DENSE", "write"): "the dense option is not built into the soak's top",
    ("MATCH", "read"): "the matcher option is not built into the soak's top (tb_stereo_frontend with matcher)",
    ("MATCH", "write"): "the matcher option is not built into the soak's top",
    "(24, 31)": "the arbiter serves the camera writers first: their FIFOs never filled beyond the levels hit "
                "(docs/camera.md: a 32-word FIFO absorbs a 3.5 us stall; the soak's faults stall the cameras, "
                "never the memory)",
    "(32, 32)": "as (24, 31): a full camera FIFO needs the memory stalled for microseconds, which no soak fault does",
    "(16, 23)": "as (24, 31)",
    "(8, 15)": "as (24, 31)",
    "(4, 7)": "as (24, 31)",
    "(0, 1)": "the highest fill between two frames read is never below 2: the read pointer reaches the write side "
              "through a two-stage synchroniser, so every camera line shows two words in flight",
}


def clock_ratio(l_mhz: float, r_mhz: float) -> str:
    d = abs(l_mhz - r_mhz) / max(l_mhz, r_mhz)
    return "equal" if d == 0 else "near" if d < 0.01 else "far" if d >= 0.10 else "other"


def _in(v, b) -> bool:
    return b[0] <= v <= b[1] if isinstance(b[0], int) else b[0] <= v < b[1]


@CoverPoint("soak.run.size", vname="size", bins=list(SIZES))
@CoverPoint("soak.run.clocks", vname="ratio", bins=list(RATIOS))
@CoverCross("soak.run.size_x_clocks", items=["soak.run.size", "soak.run.clocks"])
def sample_run(size: str, ratio: str) -> None:
    """One soak run's frame size and camera clock ratio."""


@CoverPoint("soak.fault.kind", vname="kind", bins=list(FAULTS))
@CoverPoint("soak.fault.mode", vname="mode", bins=list(MODES))
@CoverCross("soak.fault.kind_x_mode", items=["soak.fault.kind", "soak.fault.mode"])
def sample_fault(kind: str, mode: str) -> None:
    """A fault injected, in the mode the system was in."""


@CoverPoint("soak.stall.host_pause", vname="frames", bins=list(PAUSE_BINS), rel=_in)
def sample_pause(frames: float) -> None:
    """A host pause's length (camera frames)."""


@CoverPoint("soak.stall.pclk_stop", vname="periods", bins=list(STOP_BINS), rel=_in)
def sample_stop(periods: int) -> None:
    """A PCLK stop's length (PCLK periods)."""


@CoverPoint("soak.stall.late_start", vname="frames", bins=list(LATE_BINS), rel=_in)
def sample_late(frames: float) -> None:
    """A late start's length (camera frames)."""


@CoverPoint("soak.register.access", xf=lambda name, op: (name, op), bins=list(REG_BINS))
def sample_register(name: str, op: str) -> None:
    """A register access on the bus."""


@CoverPoint("soak.fifo.level", vname="level", bins=list(FIFO_BINS), rel=_in)
def sample_fifo(level: int) -> None:
    """The highest fill of a camera FIFO since the last sample."""


def register_of(address: int) -> str | None:
    """The register an AXI4-Lite byte address falls in (None outside the map)."""
    for r in REGMAP:
        if r.offset <= address < r.offset + r.span:
            return r.name
    return None


def export(path: Path) -> None:
    """This run's coverage database as YAML (cocotb-coverage's format)."""
    coverage_db.export_to_yaml(str(path))


def merge(files, out: Path) -> Path:
    """The runs' databases merged into one (cocotb-coverage's merge_coverage)."""
    files = [str(f) for f in files]
    if not files:
        raise ValueError("no coverage files to merge")
    Path(out).parent.mkdir(parents=True, exist_ok=True)
    merge_coverage(lambda *a: None, str(out), *files)
    return Path(out)


def report(merged: Path) -> tuple[list[str], list[tuple[str, str, str]]]:
    """Markdown lines for the merged database, and the holes: (coverpoint, bin, reason)."""
    import yaml

    db = yaml.safe_load(Path(merged).read_text())
    lines = ["| coverpoint | bins | hit | coverage |", "|---|---:|---:|---:|"]
    holes = []
    for name in sorted(db):
        item = db[name]
        bins = item.get("bins:_hits")
        if bins is None:  # a group node
            continue
        hit = sum(1 for v in bins.values() if v >= item.get("at_least", 1))
        lines.append(f"| `{name}` | {len(bins)} | {hit} | {100 * hit / max(1, len(bins)):.0f} % |")
        for b, v in bins.items():
            if v < item.get("at_least", 1):
                key = b if isinstance(b, str) else str(b)
                reason = HOLE_REASONS.get(key) or HOLE_REASONS.get(_as_tuple(key)) or \
                    _cross_reason(key) or "not reached (no reason known: a hole to close)"
                holes.append((name, key, reason))
    return lines, holes


def _as_tuple(key: str):
    try:
        import ast

        v = ast.literal_eval(key)
        return v if isinstance(v, tuple) else None
    except (ValueError, SyntaxError):
        return None


def _cross_reason(key: str) -> str | None:
    """A cross bin's reason from its parts' (e.g. a size x clocks pair the runs do not combine)."""
    t = _as_tuple(key)
    if t and len(t) == 2 and t[0] in SIZES and t[1] in RATIOS:
        return "the soak's runs do not combine this size with this clock ratio (the plan crosses the sizes with " \
               "the near ratio and the small size with all three)"
    return None
