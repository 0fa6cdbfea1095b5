"""Architecture rules.

* Layers: tools imports neither myhdl nor cocotb (nor hdl/sim); hdl never imports sim or cocotb. Checked
  twice: statically, by parsing every module with ``ast`` (also catches imports inside functions), and
  dynamically, by importing each tools module in a fresh interpreter and looking at ``sys.modules``.
* Sub-packages of tools (:data:`ALLOWED`): the core modules (fixed, packed, stream, testpattern, io,
  progress) import no sub-package; models import only the core; rectify the core; matching the core and
  the models; cli everything but the reports; the reports everything.
* Rooms of hdl and sim (docs/architecture.md): no block imports the EDA flow (``eyestereo.hdl.flow``);
  a bench (``eyestereo.sim.benches``) imports no other bench.
* No internals across modules: no module of tools imports a ``_private`` name from another module or
  reaches into one through ``module._name``.
"""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PACKAGES = {"tools": "eyestereo.tools", "hdl": "eyestereo.hdl", "sim": "eyestereo.sim"}

FORBIDDEN = {
    "tools": ("myhdl", "cocotb", "cocotb_tools", "eyestereo.hdl", "eyestereo.sim"),
    "hdl": ("cocotb", "cocotb_tools", "eyestereo.sim"),
}


def py_files(folder: str) -> list[Path]:
    return sorted((ROOT / folder).rglob("*.py"))


def module_name(folder: str, path: Path) -> str:
    rel = path.relative_to(ROOT / folder).with_suffix("")
    parts = [p for p in rel.parts if p != "__init__"]
    return ".".join([PACKAGES[folder], *parts])


def imported_modules(path: Path, package: str) -> list[tuple[int, str]]:
    """(line, absolute module name) of every import in the file, relative imports resolved against
    ``package`` (the package holding the file; for an ``__init__.py``, the package itself).

    ``from a import b`` yields both ``a`` and ``a.b`` (b may be a submodule). Calls of
    ``importlib.import_module("x")`` and ``__import__("x")`` with a literal name count too.
    """
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [(node.lineno, a.name) for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:  # relative to `package`, the package that contains the file
                parts = package.split(".")
                base = parts[: len(parts) - (node.level - 1)]
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            found.append((node.lineno, mod))
            found += [(node.lineno, f"{mod}.{a.name}") for a in node.names if a.name != "*"]
        elif isinstance(node, ast.Call) and node.args and isinstance(node.args[0], ast.Constant):
            f = node.func
            name = f.attr if isinstance(f, ast.Attribute) else f.id if isinstance(f, ast.Name) else None
            if name in ("import_module", "__import__") and isinstance(node.args[0].value, str):
                found.append((node.lineno, node.args[0].value))
    return found


def is_forbidden(mod: str, forbidden: tuple[str, ...]) -> bool:
    return any(mod == f or mod.startswith(f + ".") for f in forbidden)


def violations(folder: str, path: Path) -> list[str]:
    package = module_name(folder, path)
    if path.name != "__init__.py":
        package = package.rsplit(".", 1)[0]
    return [f"{path.relative_to(ROOT)}:{line} imports {mod}"
            for line, mod in imported_modules(path, package) if is_forbidden(mod, FORBIDDEN[folder])]


# --------------------------------------------------------------------------------------------------
# The checker itself


def test_checker_finds_forbidden_imports(tmp_path):
    bad = tmp_path / "bad.py"
    bad.write_text(
        "import numpy\n"
        "import myhdl\n"
        "from cocotb.triggers import RisingEdge\n"
        "def f():\n"
        "    from eyestereo.hdl import harris_mono\n"
        "    import importlib; importlib.import_module('cocotb_tools.runner')\n"
        "from eyestereo import sim\n"
        "from ..sim import bench\n"
    )
    mods = [m for _, m in imported_modules(bad, "eyestereo.tools")]
    hits = sorted({m for m in mods if is_forbidden(m, FORBIDDEN["tools"])})
    assert "numpy" not in hits
    assert {"myhdl", "cocotb.triggers", "eyestereo.hdl", "cocotb_tools.runner", "eyestereo.sim",
            "eyestereo.sim.bench"} <= set(hits)
    assert not is_forbidden("myhdlish", ("myhdl",))
    assert not is_forbidden("eyestereo.hdlx", ("eyestereo.hdl",))


def test_relative_imports_resolve(tmp_path):
    p = tmp_path / "mod.py"
    p.write_text("from . import window\nfrom .stream import TOKEN\nfrom ..hdl.interfaces.stream import ImageStream\n")
    mods = {m for _, m in imported_modules(p, "eyestereo.tools")}
    assert {"eyestereo.tools.window", "eyestereo.tools.stream", "eyestereo.hdl.interfaces.stream"} <= mods


def test_there_are_modules_to_check():
    names = {p.name for p in py_files("tools")}
    assert {"__init__.py", "stream.py", "sobel.py", "convolve.py"} <= names
    assert {"__init__.py", "stream.py", "catalog.py"} <= {p.name for p in py_files("hdl")}


# --------------------------------------------------------------------------------------------------
# Static check


@pytest.mark.parametrize("path", py_files("tools"), ids=lambda p: f"tools/{p.relative_to(ROOT / 'tools')}")
def test_tools_module_imports_no_hdl_or_simulator(path):
    assert violations("tools", path) == []


@pytest.mark.parametrize("path", py_files("hdl"), ids=lambda p: f"hdl/{p.relative_to(ROOT / 'hdl')}")
def test_hdl_module_imports_no_sim_or_cocotb(path):
    assert violations("hdl", path) == []


# --------------------------------------------------------------------------------------------------
# Rooms of hdl and sim (docs/architecture.md)

FLOW = "eyestereo.hdl.flow"
BENCHES = "eyestereo.sim.benches"
#: bench -> the benches it still borrows helpers from (to move into sim/lib in a later step of issue 22);
#: the test fails when one of these goes away, so the list shrinks with the code
KNOWN_BENCH_IMPORTS = {
    "tb_camera_stream": {"tb_camera_interface"},
    "tb_coordinate_warper": {"tb_poly_unit"},
    "tb_fetch_interpolate": {"tb_rectifier"},
    "tb_harris_cli": {"tb_harris_stereo"},
}


def imports_of(folder: str, path: Path) -> set[str]:
    mod = module_name(folder, path)
    package = mod if path.name == "__init__.py" else mod.rsplit(".", 1)[0]
    return {m for _, m in imported_modules(path, package)}


def test_rooms_exist():
    rooms = {p.parent.name for p in py_files("hdl") if p.parent != ROOT / "hdl"}
    assert {"interfaces", "common", "streaming", "harris", "rectify", "camera", "memory", "axi", "system",
            "flow"} <= rooms
    assert not [p.name for p in (ROOT / "hdl").glob("*.py") if p.name != "__init__.py"]
    assert not [p.name for p in (ROOT / "sim").glob("*.py") if p.name != "__init__.py"]
    assert all((p / "__init__.py").exists() for p in [*(ROOT / "hdl").iterdir(), *(ROOT / "sim").iterdir()]
               if p.is_dir() and p.name != "__pycache__")


@pytest.mark.parametrize("path", [p for p in py_files("hdl") if "flow" not in p.relative_to(ROOT / "hdl").parts],
                         ids=lambda p: f"hdl/{p.relative_to(ROOT / 'hdl')}")
def test_no_block_imports_the_flow(path):
    assert not [m for m in imports_of("hdl", path) if is_forbidden(m, (FLOW,))]


@pytest.mark.parametrize("path", py_files("sim/benches"), ids=lambda p: f"sim/benches/{p.name}")
def test_bench_imports_no_other_bench(path):
    own = path.stem
    others = {m.split(".")[3] for m in imports_of("sim", path)
              if m.startswith(BENCHES + ".") and len(m.split(".")) >= 4} - {own}
    assert others == KNOWN_BENCH_IMPORTS.get(own, set())


def test_hdl_reexports_every_catalogue_block():
    r = subprocess.run([sys.executable, "-c",
                        "import eyestereo.hdl as H; from eyestereo.hdl.flow.catalog import BLOCKS; "
                        "fs = {b.func for b in BLOCKS.values()}; "
                        "missing = sorted(f.__name__ for f in fs if getattr(H, f.__name__, None) is not f); "
                        "assert not missing, missing; [getattr(H, n) for n in H.__all__]"],
                       capture_output=True, text=True, cwd=ROOT, timeout=120)
    assert r.returncode == 0, r.stderr


# --------------------------------------------------------------------------------------------------
# Sub-packages of tools

CORE = "core"
#: What each part of tools may import from tools (``core`` = the top-level modules of eyestereo.tools).
ALLOWED = {
    CORE: {CORE},
    # The rectification hardware's models are built on the toolbox's own bit-true evaluator
    # (rectify.ffc.fixed_stages_codes): one definition of that arithmetic. rectify imports no model.
    "models": {CORE, "models", "rectify"},
    "rectify": {CORE, "rectify"},
    "matching": {CORE, "models", "matching"},
    "cli": {CORE, "models", "rectify", "matching", "cli"},
    "reports": {CORE, "models", "rectify", "matching", "cli", "reports"},
}


def tools_part(module: str) -> str | None:
    """The part of tools a module belongs to (a sub-package name or CORE), None outside tools."""
    if module == "eyestereo.tools":
        return CORE
    if not module.startswith("eyestereo.tools."):
        return None
    head = module.split(".")[2]
    return head if head in ALLOWED and head != CORE else CORE


def part_violations(path: Path) -> list[str]:
    mod = module_name("tools", path)
    package = mod if path.name == "__init__.py" else mod.rsplit(".", 1)[0]
    own = tools_part(mod)
    out = []
    for line, imp in imported_modules(path, package):
        other = tools_part(imp)
        if other is not None and other not in ALLOWED[own]:
            out.append(f"{path.relative_to(ROOT)}:{line} ({own}) imports {imp} ({other})")
    return out


def private_uses(path: Path, package: str) -> list[str]:
    """``from eyestereo.x import _name`` and ``alias._name`` (alias an imported eyestereo module) in a file."""
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    aliases = set()
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            aliases |= {a.asname or a.name for a in node.names if a.name.startswith("eyestereo.")}
        elif isinstance(node, ast.ImportFrom):
            mod = node.module or ""
            if node.level:
                parts = package.split(".")
                mod = ".".join(parts[: len(parts) - (node.level - 1)] + ([node.module] if node.module else []))
            if mod.startswith("eyestereo"):
                for a in node.names:
                    if a.name.startswith("_") and not a.name.startswith("__"):
                        out.append(f"{path.name}:{node.lineno} imports {mod}.{a.name}")
                    else:
                        aliases.add(a.asname or a.name)
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute) and node.attr.startswith("_") and not node.attr.startswith("__"):
            base = node.value
            if isinstance(base, ast.Name) and base.id in aliases:
                out.append(f"{path.name}:{node.lineno} uses {base.id}.{node.attr}")
    return out


def test_part_checker_and_private_checker_can_fail(tmp_path):
    assert tools_part("eyestereo.tools.models.sobel") == "models" and tools_part("eyestereo.tools.io") == CORE
    assert tools_part("eyestereo.hdl.harris.sobel") is None
    bad = tmp_path / "bad.py"
    bad.write_text("from eyestereo.tools.cli.main import _positive\n"
                   "from eyestereo.tools.rectify import calib as C\n"
                   "import eyestereo.tools.fixed\n"
                   "x = C._load_gray\n"
                   "y = eyestereo.tools.fixed._x\n")
    found = private_uses(bad, "eyestereo.tools.reports")
    assert len(found) == 2 and "_positive" in found[0] and "C._load_gray" in found[1]


@pytest.mark.parametrize("path", py_files("tools"), ids=lambda p: f"tools/{p.relative_to(ROOT / 'tools')}")
def test_tools_part_imports_only_what_its_layer_allows(path):
    assert part_violations(path) == []


@pytest.mark.parametrize("path", py_files("tools"), ids=lambda p: f"tools/{p.relative_to(ROOT / 'tools')}")
def test_no_private_names_across_modules(path):
    mod = module_name("tools", path)
    package = mod if path.name == "__init__.py" else mod.rsplit(".", 1)[0]
    assert private_uses(path, package) == []


# --------------------------------------------------------------------------------------------------
# Dynamic check

CHECK = (
    "import importlib, sys; importlib.import_module({mod!r}); "
    "bad = sorted(m for m in sys.modules if m.split('.')[0] in ('myhdl', 'cocotb', 'cocotb_tools') "
    "or m.startswith(('eyestereo.hdl', 'eyestereo.sim'))); "
    "assert not bad, bad"
)


def run_check(mod: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", CHECK.format(mod=mod)], capture_output=True, text=True,
                          cwd=ROOT, timeout=60)


@pytest.mark.parametrize("mod", [module_name("tools", p) for p in py_files("tools")])
def test_importing_tools_module_loads_no_myhdl_or_cocotb(mod):
    r = run_check(mod)
    assert r.returncode == 0, f"import {mod}:\n{r.stderr}"


def test_dynamic_check_can_fail():
    r = run_check("eyestereo.hdl.interfaces.stream")  # imports myhdl, so the check must complain
    assert r.returncode != 0
    assert "myhdl" in r.stderr
