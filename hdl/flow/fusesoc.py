"""FuseSoC cores (CAPI2) for the generated VHDL: ``make vhdl`` writes one ``<entity>.core`` per block.

A FuseSoC user adds the folder as a library and uses the blocks like any other core::

    make vhdl                                          # build/vhdl/*.vhd and *.core
    fusesoc library add eyestereo build/vhdl           # or: fusesoc --cores-root build/vhdl ...
    fusesoc core list                                  # eyestereo:blocks:sobel:0.1.0, ...
    fusesoc run --target sim eyestereo:blocks:sobel    # GHDL analyses, elaborates and runs the block

Each block core depends on ``eyestereo:lib:pck_myhdl_011`` (MyHDL's VHDL support package, one core for
all blocks); its ``default`` target names the block's entity as toplevel, so a core that depends on it
gets the VHDL files in the right order. The ``sim`` target is a smoke run of the bare block in GHDL
(edalize's flow API, ``--std=08``, 1 us with its inputs undriven): the benches with stimulus and models
are eyestereo's cocotb regressions. The VHDL is the default configuration of each block; other
configurations come from :func:`eyestereo.hdl.flow.convert.convert` (``make vhdl`` converts only defaults).
"""

from __future__ import annotations

import json
from pathlib import Path

VENDOR = "eyestereo"
LIBRARY = "blocks"


def package_core_name(package_file: str) -> str:
    return f"{VENDOR}:lib:{Path(package_file).stem}"


def _q(text: str) -> str:
    return json.dumps(str(text))  # a JSON string is a YAML string


def package_core(package_file: str, myhdl_version: str) -> str:
    return "\n".join([
        "CAPI=2:",
        f"name: {package_core_name(package_file)}:{myhdl_version}",
        f"description: {_q('MyHDL support package of the eyestereo VHDL (shared by every block)')}",
        "",
        "filesets:",
        "  rtl:",
        f"    files: [{_q(package_file)}]",
        "    file_type: vhdlSource-2008",
        "",
        "targets:",
        "  default:",
        "    filesets: [rtl]",
        ""])


def block_core(block: dict, package_file: str, version: str) -> str:
    """The CAPI2 text of one manifest entry (``entity``, ``summary``, ``files``, ``parameters``)."""
    entity = block["entity"]
    params = ", ".join(f"{k}={v}" for k, v in block.get("parameters", {}).items())
    files = [f for f in block["files"] if f != package_file]
    return "\n".join([
        "CAPI=2:",
        f"name: {VENDOR}:{LIBRARY}:{entity}:{version}",
        f"description: {_q(block['summary'] + (' [' + params + ']' if params else ''))}",
        "",
        "filesets:",
        "  rtl:",
        f"    depend: [{_q(package_core_name(package_file))}]",
        "    files: [" + ", ".join(_q(f) for f in files) + "]",
        "    file_type: vhdlSource-2008",
        "",
        "targets:",
        "  default: &default",
        "    filesets: [rtl]",
        f"    toplevel: {entity}",
        "  sim:",
        "    <<: *default",
        "    description: smoke run of the bare block in GHDL (the cocotb benches are eyestereo's)",
        "    flow: sim",
        "    flow_options:",
        "      tool: ghdl",
        "      sim_options: [--ieee-asserts=disable, --stop-time=1us]",
        ""])


def write_cores(out: Path, manifest: dict, version: str | None = None) -> list[Path]:
    """Write ``<entity>.core`` for every manifest block and the package core into ``out``."""
    import myhdl

    if version is None:
        from importlib.metadata import PackageNotFoundError, version as dist_version

        try:
            version = dist_version("eyestereo")
        except PackageNotFoundError:
            version = "0.0.0"
    out = Path(out)
    pck = manifest["package"]
    written = [out / f"{Path(pck).stem}.core"]
    written[0].write_text(package_core(pck, myhdl.__version__))
    for b in manifest["blocks"]:
        p = out / f"{b['entity']}.core"
        p.write_text(block_core(b, pck, version))
        written.append(p)
    return written
