"""Architecture rules (docs/architecture.md), read from the code with ``ast`` (imports inside functions count).

* Layers: tools imports neither myhdl nor cocotb (nor hdl/sim); hdl never imports sim or cocotb. Checked
  twice: statically, by parsing every module, and dynamically, by importing each tools module in a fresh
  interpreter and looking at ``sys.modules``.
* Rooms: :data:`ROOMS`, one table for tools' parts and the rooms of hdl and sim, says which rooms each room
  may import; every import between rooms follows it. The table itself points down :data:`TIERS` (no
  upward arrow; the only pair that imports each other is the port bundles and the checks on them), and so
  does every import in the code.
* No import circle between modules anywhere in tools, hdl and sim.
* A bench (``eyestereo.sim.benches``) imports no other bench; what benches share lives in ``sim/lib``.
* No internals across modules: no module imports a ``_private`` name from another module or reaches into
  one through ``module._name``.
* docs/architecture.md's "may import" columns say what :data:`ROOMS` says, and its picture of the import
  graph (docs/img/architecture/imports.svg, ``make architecture``) is the one the code gives today.

Imports that break a rule and are being removed by work in progress are listed in the ``BEING_REMOVED_*``
sets below; a test fails when an entry is no longer needed, so the sets only shrink.
"""

from __future__ import annotations

import ast
import subprocess
import sys
from functools import cache
from pathlib import Path

import pytest

from eyestereo.sim.measure import import_graph as graph
from eyestereo.sim.measure.import_graph import (PACKAGES, circles, doc_may_import, imported_modules, module_graph,
                                                module_name, modules, package_of, py_files, resolve, room_of)

ROOT = Path(__file__).resolve().parents[2]

FORBIDDEN = {
    "tools": ("myhdl", "cocotb", "cocotb_tools", "eyestereo.hdl", "eyestereo.sim"),
    "hdl": ("cocotb", "cocotb_tools", "eyestereo.sim"),
}

# --------------------------------------------------------------------------------------------------
# The table

#: Every part of tools (``core`` = its top-level modules): any room of hdl and sim may import them.
TOOLS = {"tools/core", "tools/models", "tools/rectify", "tools/matching", "tools/dense", "tools/cli", "tools/reports",
         "tools/board"}
#: The rooms of hdl that hold blocks (and the port bundles and helpers they are made of).
BLOCKS = {f"hdl/{r}" for r in ("interfaces", "common", "streaming", "harris", "rectify", "camera", "memory", "axi",
                                 "dense", "matching", "video", "serial")}
#: All of hdl: the block rooms, the top, the EDA flow and the package itself (``eyestereo.hdl``, which
#: re-exports the blocks).
HDL = BLOCKS | {"hdl/system", "hdl/boards", "hdl/flow", "hdl"}

#: room -> the rooms it may import (besides itself). The rows of hdl and sim are docs/architecture.md's tables.
ROOMS = {
    # tools: the core imports no part; the rectification hardware's models are built on the toolbox's own
    # bit-true evaluator (rectify.ffc.fixed_stages_codes), so models import rectify, never the reverse
    "tools/core": set(),
    "tools/rectify": {"tools/core"},
    "tools/models": {"tools/core", "tools/rectify"},
    "tools/matching": {"tools/core", "tools/models"},
    # dense stereo's reference, data sets and accuracy page stand on the models (census, sgm, dense_stereo)
    "tools/dense": {"tools/core", "tools/models"},
    # the board's host side (issue 27): the bridge's protocol model and the register map's driver
    "tools/board": {"tools/core", "tools/models"},
    "tools/cli": {"tools/core", "tools/models", "tools/rectify", "tools/matching", "tools/board"},
    "tools/reports": {"tools/core", "tools/models", "tools/rectify", "tools/matching", "tools/cli", "tools/board"},
    # hdl: every room may import tools; no block room imports system or flow
    "hdl/interfaces": TOOLS | {"hdl/common"},
    "hdl/common": TOOLS | {"hdl/interfaces"},
    "hdl/streaming": TOOLS | {"hdl/common", "hdl/interfaces"},
    "hdl/harris": TOOLS | {"hdl/common", "hdl/interfaces", "hdl/streaming"},
    "hdl/rectify": TOOLS | {"hdl/common", "hdl/interfaces"},
    "hdl/camera": TOOLS | {"hdl/common", "hdl/interfaces", "hdl/streaming"},
    "hdl/memory": TOOLS | {"hdl/common", "hdl/interfaces"},
    "hdl/axi": TOOLS | {"hdl/common", "hdl/interfaces"},
    # dense stereo (issue 28): census on the library's window machinery
    "hdl/dense": TOOLS | {"hdl/common", "hdl/interfaces", "hdl/streaming"},
    # the hardware feature matcher (issue 29): the engine; its front half will take the census from dense
    "hdl/matching": TOOLS | {"hdl/common", "hdl/interfaces", "hdl/streaming", "hdl/dense"},
    # the board's own blocks (issue 27): the monitor output and the host's serial link
    "hdl/video": TOOLS | {"hdl/common", "hdl/interfaces"},
    "hdl/serial": TOOLS | {"hdl/common", "hdl/interfaces"},
    "hdl/system": TOOLS | BLOCKS,
    # a board's top: the front end and the board's blocks around it
    "hdl/boards": TOOLS | BLOCKS | {"hdl/system"},
    "hdl/flow": TOOLS | BLOCKS | {"hdl/system", "hdl/boards"},
    "hdl": TOOLS | BLOCKS | {"hdl/system", "hdl/boards"},
    # sim: every room may import tools and hdl; measure is the top (it measures and documents the apps),
    # so apps never import measure; a bench imports no other bench (test_bench_imports_no_other_bench)
    "sim": set(),
    "sim/lib": TOOLS | HDL,
    "sim/harnesses": TOOLS | HDL | {"sim/lib"},
    "sim/benches": TOOLS | HDL | {"sim/lib"},
    "sim/apps": TOOLS | HDL | {"sim/lib"},
    "sim/measure": TOOLS | HDL | {"sim/lib", "sim/benches", "sim/harnesses", "sim/apps"},
}

#: The rooms from the bottom up: a room imports only rooms of lower tiers, except that the two rooms of
#: :data:`BASE` import each other (the port bundles use the checks, the checks know the bundles).
TIERS = [
    {"tools/core"}, {"tools/rectify"}, {"tools/models"}, {"tools/matching", "tools/dense", "tools/board"},
    {"tools/cli"}, {"tools/reports"},
    {"hdl/interfaces", "hdl/common"},
    {"hdl/streaming"},
    {"hdl/harris", "hdl/rectify", "hdl/camera", "hdl/memory", "hdl/axi", "hdl/dense", "hdl/video", "hdl/serial"},
    {"hdl/matching"},
    {"hdl/system"},
    {"hdl/boards"},
    {"hdl/flow", "hdl"},
    {"sim", "sim/lib"},
    {"sim/harnesses"},
    {"sim/benches", "sim/apps"},
    {"sim/measure"},
]
BASE = {"hdl/interfaces", "hdl/common"}

# Being removed (issue 22, work in progress): delete an entry when its import is gone (a test says when).
#: (module, room it imports) that break ROOMS or TIERS.
BEING_REMOVED_ARROWS: set[tuple[str, str]] = set()
#: bench -> the benches it still borrows helpers from (they move into sim/lib).
BEING_REMOVED_BENCH_IMPORTS: dict[str, set[str]] = {}
#: (file, private name of another module it uses).
BEING_REMOVED_PRIVATE: set[tuple[str, str]] = set()

# --------------------------------------------------------------------------------------------------
# The checkers


def all_files() -> list[tuple[str, Path]]:
    return [(folder, p) for folder in PACKAGES for p in py_files(folder)]


def file_id(item) -> str:
    return str(item[1].relative_to(ROOT))


@cache
def known() -> dict[str, Path]:
    return modules()


@cache
def library_graph() -> dict[str, dict[str, int]]:
    return module_graph(known())


def is_forbidden(mod: str, forbidden: tuple[str, ...]) -> bool:
    return any(mod == f or mod.startswith(f + ".") for f in forbidden)


def violations(folder: str, path: Path) -> list[str]:
    """Imports of a module of ``folder`` that its layer forbids (:data:`FORBIDDEN`)."""
    package = package_of(module_name(folder, path), path)
    return [f"{path.relative_to(ROOT)}:{line} imports {mod}"
            for line, mod in imported_modules(path, package) if is_forbidden(mod, FORBIDDEN[folder])]


def arrows(mod: str, path: Path, mods) -> list[tuple[int, str]]:
    """(line, module of the library) of every import of ``mod`` (in ``path``) but of itself, each once."""
    out = set()
    for line, name in imported_modules(path, package_of(mod, path)):
        target = resolve(name, mods)
        if target is not None and target != mod:
            out.add((line, target))
    return sorted(out)


def tier(room: str) -> int:
    return next(i for i, t in enumerate(TIERS) if room in t)


def goes_down(room: str, other: str) -> bool:
    return tier(other) < tier(room) or (room in BASE and other in BASE)


def room_violations(mod: str, path: Path, mods) -> list[str]:
    """The imports of ``mod`` that :data:`ROOMS` does not allow, and those that go up :data:`TIERS`."""
    own = room_of(mod)
    out = []
    seen = set()  # one message per line and room (``from a import b`` names a and a.b)
    for line, target in arrows(mod, path, mods):
        other = room_of(target)
        if other == own or (mod, other) in BEING_REMOVED_ARROWS or (line, other) in seen:
            continue
        seen.add((line, other))
        if other not in ROOMS[own]:
            out.append(f"line {line}: {own} may not import {other} ({target})")
        if not goes_down(own, other):
            out.append(f"line {line}: upward import, {own} imports {other} ({target})")
    return out


def private_uses(path: Path, package: str) -> list[tuple[int, str]]:
    """(line, ``module._name``) of every private name of another module of the library that a file uses:
    ``from eyestereo.x import _name``, and ``alias._name`` where ``alias`` is an imported module of the
    library (``import eyestereo.x as alias``, ``from eyestereo import x``, ``import eyestereo.x``)."""
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    aliases: dict[str, str] = {}
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            aliases.update({a.asname or a.name: a.name for a in node.names if a.name.startswith("eyestereo.")})
        elif isinstance(node, ast.ImportFrom):
            mod = graph.absolute(node, package)
            if mod.startswith("eyestereo"):
                for a in node.names:
                    if a.name.startswith("_") and not a.name.startswith("__"):
                        out.append((node.lineno, f"{mod}.{a.name}"))
                    else:
                        aliases[a.asname or a.name] = f"{mod}.{a.name}"
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute) and node.attr.startswith("_") and not node.attr.startswith("__"):
            base = node.value
            if isinstance(base, (ast.Name, ast.Attribute)) and ast.unparse(base) in aliases:
                out.append((node.lineno, f"{aliases[ast.unparse(base)]}.{node.attr}"))
    return out


def other_benches(path: Path, root: Path = ROOT) -> set[str]:
    """The benches (``eyestereo.sim.benches.<bench>``) that a bench imports, but itself."""
    mod = module_name("sim", path, root)
    names = {m for _, m in imported_modules(path, package_of(mod, path))}
    return {m.split(".")[3] for m in names if m.startswith("eyestereo.sim.benches.")} - {path.stem}


# --------------------------------------------------------------------------------------------------
# The checkers can fail


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


def test_rooms_of_modules():
    assert room_of("eyestereo.tools.models.sobel") == "tools/models" and room_of("eyestereo.tools.io") == "tools/core"
    assert room_of("eyestereo.tools") == "tools/core"
    assert room_of("eyestereo.hdl.harris.sobel") == "hdl/harris" and room_of("eyestereo.hdl") == "hdl"
    assert room_of("eyestereo.sim.lib.runner") == "sim/lib" and room_of("numpy") is None
    mods = known()
    assert resolve("eyestereo.hdl.harris.sobel.sobel", mods) == "eyestereo.hdl.harris.sobel"
    assert resolve("eyestereo.hdl.harris_mono", mods) == "eyestereo.hdl"  # through the package's re-exports
    assert resolve("numpy.linalg", mods) is None


def test_room_checker_can_fail(tmp_path):
    bad = tmp_path / "bad.py"
    bad.write_text("from eyestereo.hdl.interfaces.stream import ImageStream\n"  # allowed
                   "from eyestereo.tools.fixed import Fixed\n"  # allowed
                   "from eyestereo.hdl import harris_mono\n"  # the package's re-exports: above every block
                   "def f():\n"
                   "    from eyestereo.hdl.harris import sobel\n"  # a block room the table does not name
                   "    import eyestereo.hdl.flow.catalog\n")  # the flow
    found = room_violations("eyestereo.hdl.streaming.bad", bad, known())
    assert len([f for f in found if "may not import" in f]) == 3
    assert len([f for f in found if "upward" in f]) == 3
    assert all(("line 3" in f) or ("line 5" in f) or ("line 6" in f) for f in found)
    # a room importing a room of its own tier is upward too (harris and rectify are siblings)
    found = room_violations("eyestereo.hdl.rectify.bad", bad, known())
    assert any("upward import, hdl/rectify imports hdl/harris" in f for f in found)
    # the same imports from the top are fine
    assert room_violations("eyestereo.sim.measure.bad", bad, known()) == []


def test_circle_finder_can_fail(tmp_path):
    (tmp_path / "tools").mkdir()
    (tmp_path / "tools" / "__init__.py").write_text("")
    (tmp_path / "tools" / "a.py").write_text("from eyestereo.tools import b\n")
    (tmp_path / "tools" / "b.py").write_text("def f():\n    from eyestereo.tools.c import x\n")  # inside a function
    (tmp_path / "tools" / "c.py").write_text("import eyestereo.tools.a\n")
    (tmp_path / "tools" / "d.py").write_text("from eyestereo.tools import a, b\n")  # imports the circle, not in it
    mods = modules(tmp_path)
    assert set(mods) == {"eyestereo.tools", *(f"eyestereo.tools.{m}" for m in "abcd")}
    assert circles(module_graph(mods)) == [["eyestereo.tools.a", "eyestereo.tools.b", "eyestereo.tools.c"]]
    assert circles({"x": {"y"}, "y": set()}) == []
    assert circles({"x": {"y"}, "y": {"x"}, "z": {"z"}}) == [["x", "y"]]


def test_private_checker_can_fail(tmp_path):
    bad = tmp_path / "bad.py"
    bad.write_text("from eyestereo.tools.cli.main import _positive\n"
                   "from eyestereo.tools.rectify import calib as C\n"
                   "import eyestereo.tools.fixed\n"
                   "from .runner import _jsonable\n"
                   "from eyestereo.tools.io import Outputs\n"
                   "x = C._load_gray\n"
                   "y = eyestereo.tools.fixed._x\n"
                   "z = Outputs._internal\n"  # a class's private member, reached through the class: found too
                   "ok = C.load, eyestereo.tools.fixed.Fixed, self._own\n")
    found = private_uses(bad, "eyestereo.sim.lib")
    assert sorted(found) == [(1, "eyestereo.tools.cli.main._positive"), (4, "eyestereo.sim.lib.runner._jsonable"),
                             (6, "eyestereo.tools.rectify.calib._load_gray"), (7, "eyestereo.tools.fixed._x"),
                             (8, "eyestereo.tools.io.Outputs._internal")]


def test_bench_checker_can_fail(tmp_path):
    bench = tmp_path / "sim" / "benches" / "tb_x.py"
    bench.parent.mkdir(parents=True)
    bench.write_text("from eyestereo.sim.benches.tb_y import helper\n"
                     "def f():\n    from . import tb_z\n"
                     "from eyestereo.sim.lib.bench import load_config\n")
    assert other_benches(bench, tmp_path) == {"tb_y", "tb_z"}


def test_doc_parser_reads_the_rows(tmp_path):
    doc = tmp_path / "architecture.md"
    doc.write_text("## hdl/ (eyestereo.hdl)\n\n| room | what | may import |\n|---|---|---|\n"
                   "| `harris` | `sobel` | `common`, `streaming.line_delay` |\n"
                   "| `system` | the top | `harris` and `tools` |\n\n"
                   "## sim/ (eyestereo.sim)\n\n| room | what | may import |\n|---|---|---|\n"
                   "| `apps` | `cli` | `lib`, `hdl` |\n\n## Notes\n\n| `benches` | not a room row here | `apps` |\n")
    rules = doc_may_import(doc)
    assert set(rules) == {"hdl/harris", "hdl/system", "sim/apps"}
    assert rules["hdl/harris"] == {"hdl/common", "hdl/streaming"} and rules["hdl/system"] == {"hdl/harris"}
    assert rules["sim/apps"] == {"sim/lib"} | HDL


# --------------------------------------------------------------------------------------------------
# The table and the rooms


def test_rooms_exist():
    rooms = {p.parent.name for p in py_files("hdl") if p.parent != ROOT / "hdl"}
    assert {"interfaces", "common", "streaming", "harris", "rectify", "camera", "memory", "axi", "system",
            "flow"} <= rooms
    assert not [p.name for p in (ROOT / "hdl").glob("*.py") if p.name != "__init__.py"]
    assert not [p.name for p in (ROOT / "sim").glob("*.py") if p.name != "__init__.py"]
    assert all((p / "__init__.py").exists() for p in [*(ROOT / "hdl").iterdir(), *(ROOT / "sim").iterdir()]
               if p.is_dir() and p.name != "__pycache__")


def test_every_room_has_a_row():
    found = {room_of(m) for m in known()}
    assert found == set(ROOMS), f"rooms without a row: {sorted(found - set(ROOMS))}; rows without a room: " \
                                f"{sorted(set(ROOMS) - found)}"


def test_the_table_points_down():
    assert sorted(r for t in TIERS for r in t) == sorted(ROOMS), "every room in exactly one tier"
    up = [f"{room} -> {other}" for room, allowed in ROOMS.items() for other in allowed if not goes_down(room, other)]
    assert up == []


@pytest.mark.parametrize("item", all_files(), ids=file_id)
def test_imports_follow_the_table(item):
    folder, path = item
    assert room_violations(module_name(folder, path), path, known()) == []


def test_no_import_circle():
    assert circles(library_graph()) == []


@pytest.mark.parametrize("path", py_files("sim/benches"), ids=lambda p: f"sim/benches/{p.name}")
def test_bench_imports_no_other_bench(path):
    assert other_benches(path) == BEING_REMOVED_BENCH_IMPORTS.get(path.stem, set())


@pytest.mark.parametrize("item", all_files(), ids=file_id)
def test_no_private_names_across_modules(item):
    folder, path = item
    rel = str(path.relative_to(ROOT))
    used = private_uses(path, package_of(module_name(folder, path), path))
    assert [f"line {line}: {name}" for line, name in used if (rel, name) not in BEING_REMOVED_PRIVATE] == []


def test_being_removed_entries_are_still_needed():
    """Each exception still matches an import of the code: delete the entries whose import is gone."""
    mods = known()
    gone = [f"{a} -> {b}" for a, b in sorted(BEING_REMOVED_ARROWS)
            if a not in mods or b not in {room_of(t) for _, t in arrows(a, mods[a], mods)}]
    for bench, others in sorted(BEING_REMOVED_BENCH_IMPORTS.items()):
        path = ROOT / "sim" / "benches" / f"{bench}.py"
        gone += [f"{bench} -> {o}" for o in sorted(others) if not path.is_file() or o not in other_benches(path)]
    for rel, name in sorted(BEING_REMOVED_PRIVATE):
        path = ROOT / rel
        folder = rel.split("/")[0]
        if not path.is_file() or name not in {n for _, n in private_uses(path, package_of(module_name(folder, path),
                                                                                             path))}:
            gone.append(f"{rel}: {name}")
    assert gone == [], "no longer needed: delete these entries"


def test_doc_tables_match_the_table():
    doc = doc_may_import()
    rooms = sorted(r for r in ROOMS if r.startswith(("hdl/", "sim/")))
    assert sorted(doc) == rooms, "docs/architecture.md: one row per room of hdl and sim"
    differ = {r: dict(doc_only=sorted(doc[r] - ROOMS[r]), table_only=sorted(ROOMS[r] - TOOLS - {r} - doc[r]))
              for r in rooms if doc[r] != ROOMS[r] - TOOLS - {r}}
    assert differ == {}


def test_picture_is_current():
    """docs/img/architecture/imports.svg is what ``make architecture`` writes today."""
    assert graph.OUT.read_text(encoding="utf-8") == graph.render(graph.picture_edges(library_graph())), \
        "run make architecture"


def test_hdl_reexports_every_catalogue_block():
    r = subprocess.run([sys.executable, "-c",
                        "import eyestereo.hdl as H; from eyestereo.hdl.flow.catalog import BLOCKS; "
                        "fs = {b.func for b in BLOCKS.values()}; "
                        "missing = sorted(f.__name__ for f in fs if getattr(H, f.__name__, None) is not f); "
                        "assert not missing, missing; [getattr(H, n) for n in H.__all__]"],
                       capture_output=True, text=True, cwd=ROOT, timeout=120)
    assert r.returncode == 0, r.stderr


# --------------------------------------------------------------------------------------------------
# Layers: static check


def test_there_are_modules_to_check():
    names = {p.name for p in py_files("tools")}
    assert {"__init__.py", "stream.py", "sobel.py", "convolve.py"} <= names
    assert {"__init__.py", "stream.py", "catalog.py"} <= {p.name for p in py_files("hdl")}


@pytest.mark.parametrize("path", py_files("tools"), ids=lambda p: f"tools/{p.relative_to(ROOT / 'tools')}")
def test_tools_module_imports_no_hdl_or_simulator(path):
    assert violations("tools", path) == []


@pytest.mark.parametrize("path", py_files("hdl"), ids=lambda p: f"hdl/{p.relative_to(ROOT / 'hdl')}")
def test_hdl_module_imports_no_sim_or_cocotb(path):
    assert violations("hdl", path) == []


# --------------------------------------------------------------------------------------------------
# Layers: dynamic check

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
