"""The import graph between the rooms, drawn from the code: docs/img/architecture/imports.svg (``make architecture``).

``python -m eyestereo.sim.measure.import_graph [--out FILE] [--check]`` parses every module of ``tools/``,
``hdl/`` and ``sim/`` with :mod:`ast` (imports inside functions too; nothing is imported or run), folds the
module imports into arrows between rooms (the sub-packages of ``hdl/`` and ``sim/``; ``tools/`` is one box)
and writes them as an SVG: one row per layer, a room above every room it imports. Rooms that import each
other (a circle between rooms) share a row, their arrows red. Only whether an arrow exists shows, not how
many imports it stands for, so the picture changes when an arrow appears or goes, not at every import.
The layout is computed here (no Graphviz): the same code gives the same file, byte for byte, so a test can
tell whether the committed picture is current.

It also reads docs/architecture.md's room tables and reports every arrow of the code that the table's
"may import" column does not allow, and every import circle between modules (``--check`` fails on these and
on a picture that is not current; without it they are printed and the picture written all the same).
``tests/core/test_layering.py`` holds the rules themselves and uses this module's parser.
"""

from __future__ import annotations

import argparse
import ast
import re
import sys
from html import escape
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
OUT = ROOT / "docs" / "img" / "architecture" / "imports.svg"
DOC = ROOT / "docs" / "architecture.md"
#: Top-level folder -> package name.
PACKAGES = {"tools": "eyestereo.tools", "hdl": "eyestereo.hdl", "sim": "eyestereo.sim"}
#: The top-level modules of tools form one part of it, ``core``.
CORE = "core"


# --------------------------------------------------------------------------------------------------
# Modules and their imports


def py_files(folder: str, root: Path = ROOT) -> list[Path]:
    return sorted((root / folder).rglob("*.py"))


def module_name(folder: str, path: Path, root: Path = ROOT) -> str:
    """``eyestereo.<folder>.<...>`` of a file below ``root/folder`` (a package's ``__init__`` is the package)."""
    rel = path.relative_to(root / folder).with_suffix("")
    parts = [p for p in rel.parts if p != "__init__"]
    return ".".join([PACKAGES[folder], *parts])


def package_of(module: str, path: Path) -> str:
    """The package a file's relative imports start from: the package itself for an ``__init__.py``."""
    return module if path.name == "__init__.py" else module.rsplit(".", 1)[0]


def imported_modules(path: Path, package: str) -> list[tuple[int, str]]:
    """(line, absolute module name) of every import in the file, relative imports resolved against
    ``package`` (the package holding the file; for an ``__init__.py``, the package itself).

    Every import counts, at the top or inside a function. ``from a import b`` yields both ``a`` and ``a.b``
    (b may be a submodule). Calls of ``importlib.import_module("x")`` and ``__import__("x")`` with a literal
    name count too.
    """
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [(node.lineno, a.name) for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            mod = absolute(node, package)
            found.append((node.lineno, mod))
            found += [(node.lineno, f"{mod}.{a.name}") for a in node.names if a.name != "*"]
        elif isinstance(node, ast.Call) and node.args and isinstance(node.args[0], ast.Constant):
            f = node.func
            name = f.attr if isinstance(f, ast.Attribute) else f.id if isinstance(f, ast.Name) else None
            if name in ("import_module", "__import__") and isinstance(node.args[0].value, str):
                found.append((node.lineno, node.args[0].value))
    return found


def absolute(node: ast.ImportFrom, package: str) -> str:
    """The module a ``from ... import`` names, a relative one resolved against ``package``."""
    if not node.level:
        return node.module or ""
    parts = package.split(".")
    return ".".join(parts[: len(parts) - (node.level - 1)] + ([node.module] if node.module else []))


def modules(root: Path = ROOT) -> dict[str, Path]:
    """Every module of tools, hdl and sim: name -> file."""
    return {module_name(folder, p, root): p for folder in PACKAGES for p in py_files(folder, root)}


def resolve(name: str, known) -> str | None:
    """The module an imported name stands for: the longest known module that ``name`` starts with
    (``eyestereo.hdl.harris.sobel.sobel`` -> ``eyestereo.hdl.harris.sobel``); None outside the library."""
    while name:
        if name in known:
            return name
        name = name.rpartition(".")[0]
    return None


def module_graph(mods: dict[str, Path]) -> dict[str, dict[str, int]]:
    """module -> {module it imports: the first line that imports it} (imports of itself left out)."""
    out: dict[str, dict[str, int]] = {}
    for mod, path in mods.items():
        edges = out.setdefault(mod, {})
        for line, name in imported_modules(path, package_of(mod, path)):
            target = resolve(name, mods)
            if target is not None and target != mod:
                edges.setdefault(target, line)
    return out


def circles(graph: dict[str, set[str] | dict]) -> list[list[str]]:
    """The import circles of a graph: its strongly connected parts of two or more nodes (Tarjan's, without
    recursion), each sorted, in sorted order."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found = []
    for start in sorted(graph):
        if start in index:
            continue
        work = [(start, iter(sorted(graph.get(start, ()))))]
        index[start] = low[start] = len(index)
        stack.append(start)
        on_stack.add(start)
        while work:
            node, targets = work[-1]
            for t in targets:
                if t not in index:
                    index[t] = low[t] = len(index)
                    stack.append(t)
                    on_stack.add(t)
                    work.append((t, iter(sorted(graph.get(t, ())))))
                    break
                if t in on_stack:
                    low[node] = min(low[node], index[t])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[node])
                if low[node] == index[node]:
                    part = []
                    while True:
                        m = stack.pop()
                        on_stack.discard(m)
                        part.append(m)
                        if m == node:
                            break
                    if len(part) > 1:
                        found.append(sorted(part))
    return sorted(found)


# --------------------------------------------------------------------------------------------------
# Rooms


def room_of(module: str, root: Path = ROOT) -> str | None:
    """The room of a module: ``hdl/<room>``, ``sim/<room>``, ``tools/<part>`` (``tools/core`` for its
    top-level modules); ``hdl`` and ``sim`` for the packages themselves; None outside the library."""
    parts = module.split(".")
    if parts[0] != "eyestereo" or len(parts) < 2 or parts[1] not in PACKAGES:
        return None
    top = parts[1]
    if top == "tools":
        sub = parts[2] if len(parts) > 2 and (root / "tools" / parts[2] / "__init__.py").is_file() else CORE
        return f"tools/{sub}"
    return top if len(parts) == 2 else f"{top}/{parts[2]}"


def room_graph(graph: dict[str, dict[str, int]], *, fold_tools: bool = False) -> dict[tuple[str, str], int]:
    """(room, room it imports) -> the count of module imports behind that arrow. ``fold_tools``: every part of
    tools as one room ``tools``."""
    def room(m):
        r = room_of(m)
        return "tools" if fold_tools and r and r.startswith("tools/") else r

    out: dict[tuple[str, str], int] = {}
    for mod, targets in graph.items():
        for t in targets:
            a, b = room(mod), room(t)
            if a != b:
                out[(a, b)] = out.get((a, b), 0) + 1
    return out


def doc_may_import(path: Path = DOC) -> dict[str, set[str]]:
    """The "may import" column of docs/architecture.md's room tables: ``hdl/<room>`` / ``sim/<room>`` -> the
    rooms named in it in backticks (``hdl`` in the sim table: every room of hdl and the package itself;
    ``streaming.line_delay``: the room ``streaming``). ``tools``, which every room may import, is left out."""
    hdl_rooms = rooms_of("hdl")
    sim_rooms = rooms_of("sim")
    out: dict[str, set[str]] = {}
    layer = None
    for line in path.read_text(encoding="utf-8").splitlines():
        head = re.match(r"## (hdl|sim)/", line)
        if head:
            layer = head.group(1)
        elif line.startswith("## "):
            layer = None
        elif layer and line.startswith("| `"):
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            room = cells[0].strip("`")
            allowed = set()
            for token in re.findall(r"`([^`]+)`", cells[-1]):
                name = token.split(".")[0]
                if layer == "sim" and name == "hdl":
                    allowed |= {"hdl"} | {f"hdl/{r}" for r in hdl_rooms}
                elif name in (hdl_rooms if layer == "hdl" else sim_rooms):
                    allowed.add(f"{layer}/{name}")
            out[f"{layer}/{room}"] = allowed
    return out


def rooms_of(top: str, root: Path = ROOT) -> list[str]:
    """The rooms (sub-packages) of ``hdl`` or ``sim``."""
    return sorted(p.name for p in (root / top).iterdir() if (p / "__init__.py").is_file())


def undocumented(edges, doc: dict[str, set[str]]) -> list[str]:
    """Arrows of the code between rooms of hdl and sim that the doc's tables do not allow."""
    return [f"{a} -> {b} ({n} imports)" for (a, b), n in sorted(edges.items())
            if a in doc and not b.startswith("tools") and b not in doc[a]]


# --------------------------------------------------------------------------------------------------
# The picture

BOX_W, BOX_H, GAP, ROW_H, MARGIN = 124, 30, 26, 78, 20
LEGEND_H = 22
FILL = {"tools": "#e8f0e0", "hdl": "#e3ecf7", "sim": "#f7ebdc"}


def ranks(nodes: list[str], edges) -> dict[str, int]:
    """Each room's row: 0 for a room that imports none of the others, else one above the highest room it
    imports (rooms in one import circle share a row)."""
    graph = {n: {b for (a, b) in edges if a == n} for n in nodes}
    part = {n: n for n in nodes}
    for c in circles(graph):
        for n in c:
            part[n] = c[0]
    rank: dict[str, int] = {}

    def rank_of(p: str) -> int:
        if p not in rank:
            members = [n for n in nodes if part[n] == p]
            below = {part[t] for n in members for t in graph[n]} - {p}
            rank[p] = 1 + max((rank_of(q) for q in sorted(below)), default=-1)
        return rank[p]

    return {n: rank_of(part[n]) for n in nodes}


def layout(nodes: list[str], edges) -> dict[str, tuple[float, float]]:
    """The centre of each room's box: rows by :func:`ranks` (the lowest at the bottom); within a row the
    rooms ordered by the mean place of the rooms they import (going up the rows), then of the rooms that
    import them (going down), to keep the arrows short."""
    rank = ranks(nodes, edges)
    rows: dict[int, list[str]] = {}
    for n in nodes:
        rows.setdefault(rank[n], []).append(n)
    top = max(rows)
    width = max(len(r) for r in rows.values()) * (BOX_W + GAP) - GAP + 2 * MARGIN

    def place() -> dict[str, float]:
        xs = {}
        for r in rows.values():
            left = (width - (len(r) * (BOX_W + GAP) - GAP)) / 2
            xs.update({n: left + i * (BOX_W + GAP) + BOX_W / 2 for i, n in enumerate(r)})
        return xs

    below = {n: [b for (a, b) in edges if a == n] for n in nodes}
    above = {n: [a for (a, b) in edges if b == n] for n in nodes}
    for order, near in ((range(1, top + 1), below), (range(top - 1, -1, -1), above)):
        for r in order:
            xs = place()
            keyed = []
            for i, n in enumerate(rows[r]):
                others = [xs[t] for t in near[n] if rank[t] != r]
                keyed.append((sum(others) / len(others) if others else xs[n], i, n))
            rows[r] = [n for _, _, n in sorted(keyed)]
    xs = place()
    return {n: (round(xs[n], 1), round(MARGIN + (top - rank[n]) * ROW_H + BOX_H / 2, 1)) for n in nodes}


def render(edges: dict[tuple[str, str], int]) -> str:
    """The SVG of a room graph (arrows importer -> imported)."""
    nodes = sorted({a for a, _ in edges} | {b for _, b in edges}, key=node_key)
    pos = layout(nodes, edges)
    rank = ranks(nodes, edges)
    width = round(max(x for x, _ in pos.values()) + BOX_W / 2 + MARGIN)
    height = round(max(y for _, y in pos.values()) + BOX_H / 2 + MARGIN + LEGEND_H)
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" '
           f'viewBox="0 0 {width} {height}" font-family="sans-serif" font-size="12">',
           "<title>eyestereo: imports between the rooms (generated by eyestereo.sim.measure.import_graph)</title>",
           '<defs><marker id="a" viewBox="0 0 10 10" refX="10" refY="5" markerWidth="7" markerHeight="7" '
           'orient="auto-start-reverse"><path d="M0,0 L10,5 L0,10 z" fill="context-stroke"/></marker></defs>',
           f'<rect width="{width}" height="{height}" fill="white"/>']
    # where each arrow leaves its importer (bottom side) and reaches the imported room (top side): spread
    # along the side in the order of the other ends, so that arrows do not start or end on one point
    leave = {n: sorted((b for (a, b) in edges if a == n), key=lambda b: (pos[b][0], b)) for n in nodes}
    reach = {n: sorted((a for (a, b) in edges if b == n), key=lambda a: (pos[a][0], a)) for n in nodes}

    def spread(n: str, others: list[str], other: str) -> float:
        i = others.index(other)
        return round(pos[n][0] - BOX_W / 2 + BOX_W * (i + 1) / (len(others) + 1), 1)

    for a, b in sorted(edges, key=lambda e: (e[1].startswith("tools"), e)):
        (xa, ya), (xb, yb) = pos[a], pos[b]
        colour, w = ("#9a9a9a", 0.8) if b == "tools" else ("#303030", 1.2)
        if rank[b] >= rank[a]:  # sideways or up: part of an import circle between rooms
            colour, w = "#d01010", 1.6
        if rank[b] == rank[a]:
            # within a row: an arc from side to side, below the boxes left to right, above right to left
            sign = 1 if xb > xa else -1
            x1, x2 = xa + sign * BOX_W / 4, xb - sign * BOX_W / 4
            y1 = ya + sign * BOX_H / 2
            bend = round(y1 + sign * (14 + abs(xb - xa) / 12), 1)
            out.append(f'<path d="M{x1},{y1} Q{round((x1 + x2) / 2, 1)},{bend} {x2},{y1}" fill="none" '
                       f'stroke="{colour}" stroke-width="{w}" marker-end="url(#a)"><title>{escape(a)} imports '
                       f'{escape(b)}</title></path>')
            continue
        line = (spread(a, leave[a], b), ya + BOX_H / 2, spread(b, reach[b], a), yb - BOX_H / 2)
        out.append(f'<line x1="{line[0]}" y1="{line[1]}" x2="{line[2]}" y2="{line[3]}" stroke="{colour}" '
                   f'stroke-width="{w}" marker-end="url(#a)"><title>{escape(a)} imports {escape(b)}</title></line>')
    for node in nodes:
        x, y = pos[node]
        count = sum(1 for (a, _) in edges if a == node)
        out.append(f'<g><title>{escape(node)}: imports {count} room{"s" if count != 1 else ""}</title>'
                   f'<rect x="{round(x - BOX_W / 2, 1)}" y="{round(y - BOX_H / 2, 1)}" width="{BOX_W}" '
                   f'height="{BOX_H}" rx="5" fill="{FILL[node.split("/")[0]]}" stroke="#404040"/>'
                   f'<text x="{x}" y="{round(y + 4, 1)}" text-anchor="middle">{escape(node)}</text></g>')
    out.append(f'<text x="{MARGIN}" y="{height - 8}" font-size="11" fill="#404040">Arrow: importer to imported; '
               'grey: to tools; red: within a row, rooms importing each other.</text>')
    return "\n".join(out + ["</svg>"]) + "\n"


def node_key(node: str) -> tuple[int, str]:
    return ({"tools": 0, "hdl": 1, "sim": 2}[node.split("/")[0]], node)


def picture_edges(mod_graph: dict[str, dict[str, int]] | None = None) -> dict[tuple[str, str], int]:
    """The arrows the picture shows (of :func:`module_graph`, by default the library's): between the rooms of
    hdl and sim and tools as one room (the packages ``eyestereo.hdl`` and ``eyestereo.sim`` themselves, which
    hold no room's code, left out)."""
    edges = room_graph(module_graph(modules()) if mod_graph is None else mod_graph, fold_tools=True)
    return {(a, b): n for (a, b), n in edges.items() if a not in ("hdl", "sim") and b not in ("hdl", "sim")
            and a != "tools"}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=OUT, help=f"the SVG (default {OUT.relative_to(ROOT)})")
    ap.add_argument("--check", action="store_true",
                    help="write nothing; fail when the picture is not current or the doc's tables miss an arrow")
    args = ap.parse_args(argv)
    mod_graph = module_graph(modules())
    edges = picture_edges(mod_graph)
    svg = render(edges)
    missing = undocumented(room_graph(mod_graph), doc_may_import())
    for m in missing:
        print(f"not in {DOC.relative_to(ROOT)}'s tables: {m}", file=sys.stderr)
    loops = circles(mod_graph)
    for c in loops:
        print(f"import circle: {' <-> '.join(c)}", file=sys.stderr)
    if args.check:
        current = args.out.is_file() and args.out.read_text(encoding="utf-8") == svg
        if not current:
            print(f"{args.out} is not current: make architecture", file=sys.stderr)
        return 0 if current and not missing and not loops else 1
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(svg, encoding="utf-8")
    print(f"{args.out.relative_to(ROOT) if args.out.is_relative_to(ROOT) else args.out}: "
          f"{len({a for a, _ in edges} | {b for _, b in edges})} rooms, {len(edges)} arrows")
    return 0


if __name__ == "__main__":
    sys.exit(main())
