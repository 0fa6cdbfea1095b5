"""Timing pictures: WaveDrom diagrams of every handshake, rendered offline, next to the ASCII ones.

``python -m eyestereo.hdl.flow.timing`` (``make timing``) renders each ``docs/wavedrom/<name>.json`` (WaveJSON)
to ``docs/img/timing/<name>.svg`` with yowasp-wavedrom (WaveDrom in a bundled JavaScript engine: no
browser, no network) and writes ``docs/timing.md``: per diagram its title, the ASCII diagram and the
SVG. The committed SVGs and ``docs/timing.md`` are this command's output.

Each JSON file carries, besides WaveDrom's ``signal``/``head``/``config``, an ``eyestereo`` object
(WaveDrom ignores it; it is removed before rendering):

``title``
    the section heading in ``docs/timing.md``;
``ascii``
    where the ASCII diagram lives: ``"module"`` or ``"module:object"`` whose docstring has a literal
    block (after ``::``) with a ``cycle`` line, e.g. ``"eyestereo.hdl.interfaces.stream"``; the diagram in the
    docs is read from there, so the two stay one;
``ascii_contains``
    optional, with ``ascii``: take the first such block that contains this text (a docstring with
    several diagrams, e.g. ``"cam"`` for the stereo stream's in ``eyestereo.hdl.interfaces.stream``);
``ascii_lines``
    instead of ``ascii``, for a contract whose interface class does not exist yet (from INTERFACES.md):
    the ASCII diagram itself;
``defined_by``
    optional: who defines the interface;
``order``
    optional sort key (default 100; then by file name).

Interfaces that are announced but have no diagram yet (:data:`EXPECTED`) are listed as "not yet
available" so that their owners know where to add one.
"""

from __future__ import annotations

import argparse
import importlib
import json
import os
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
JSON_DIR = ROOT / "docs" / "wavedrom"
SVG_DIR = ROOT / "docs" / "img" / "timing"
DOC = ROOT / "docs" / "timing.md"

#: Diagrams the system needs whose interfaces other work items define: file stem -> what it is.
EXPECTED = {
    "sram": "SRAM pins and the controller's word port (the SRAM work, issue 12)",
    "register_bus": "Register bus, Wishbone B4 or AXI4-Lite (the complete system, issue 15)",
    "feature_words": "Feature words (the stereo Harris work, issue 14)",
}


class TimingError(ValueError):
    """A diagram file is broken (bad JSON, no title, an ASCII source that does not resolve)."""


def load(path: Path) -> dict:
    try:
        d = json.loads(Path(path).read_text())
    except (OSError, json.JSONDecodeError) as e:
        raise TimingError(f"{path}: {e}") from None
    meta = d.get("eyestereo")
    if not isinstance(d.get("signal"), list) or not isinstance(meta, dict) or not meta.get("title"):
        raise TimingError(f"{path}: needs a 'signal' list and an 'eyestereo' object with a 'title'")
    if ("ascii" in meta) == ("ascii_lines" in meta):
        raise TimingError(f"{path}: the 'eyestereo' object needs exactly one of 'ascii' and 'ascii_lines'")
    _check_waves(path, d["signal"])
    return d


def _check_waves(path: Path, signals) -> None:
    """Every wave one character per clock, as long as the first; one data label per data character."""
    length = None
    for s in signals:
        for item in (s[1:] if isinstance(s, list) else [s]):
            if not isinstance(item, dict) or "wave" not in item:
                continue
            w = item["wave"]
            length = length or len(w)
            if len(w) != length:
                raise TimingError(f"{path}: wave of {item.get('name')!r} has {len(w)} clocks, the first has {length}")
            if "data" in item:
                n = sum(c in "=2345" for c in w)
                if n != len(item["data"]):
                    raise TimingError(f"{path}: {item.get('name')!r} has {n} data slots and {len(item['data'])} labels")


def render(d: dict) -> str:
    """The SVG of a WaveJSON diagram (our ``eyestereo`` metadata left out)."""
    import yowasp_wavedrom

    src = {k: v for k, v in d.items() if k != "eyestereo"}
    svg = yowasp_wavedrom.render(src)
    if not isinstance(svg, str) or "<svg" not in svg[:200]:
        raise TimingError(f"WaveDrom returned no SVG for {d['eyestereo']['title']!r}")
    return svg


def ascii_block(doc: str, contains: str | None = None) -> str:
    """The first literal block (after ``::``) of a docstring that contains a ``cycle`` line (and
    ``contains``, when given), dedented."""
    lines = doc.splitlines()
    for i, line in enumerate(lines):
        if not line.rstrip().endswith("::"):
            continue
        block: list[str] = []
        for l in lines[i + 1:]:
            if l.strip() and not l.startswith((" ", "\t")):
                break
            if l.strip() and block and len(l) - len(l.lstrip()) <= len(lines[i]) - len(lines[i].lstrip()):
                break
            block.append(l)
        text = "\n".join(block).strip("\n")
        if re.search(r"^\s*cycle\b", text, re.M) and (contains is None or contains in text):
            indent = min(len(l) - len(l.lstrip()) for l in text.splitlines() if l.strip())
            return "\n".join(l[indent:] for l in text.splitlines())
    raise TimingError("no literal block with a 'cycle' line in the docstring")


def ascii_for(meta: dict) -> tuple[str, str]:
    """(ASCII diagram, where it comes from) for a diagram's metadata."""
    if "ascii_lines" in meta:
        return "\n".join(meta["ascii_lines"]), "INTERFACES.md contract (no interface class yet)"
    mod, _, obj = meta["ascii"].partition(":")
    try:
        target = importlib.import_module(mod)
        for part in filter(None, obj.split(".")):
            target = getattr(target, part)
    except (ImportError, AttributeError) as e:
        raise TimingError(f"ASCII source {meta['ascii']!r} does not resolve: {e}") from None
    try:
        return ascii_block(target.__doc__ or "", meta.get("ascii_contains")), f"docstring of `{meta['ascii']}`"
    except TimingError as e:
        raise TimingError(f"{meta['ascii']}: {e}") from None


def diagrams(json_dir: Path = JSON_DIR) -> list[tuple[str, dict]]:
    """(stem, diagram) of every JSON file, in document order."""
    items = [(p.stem, load(p)) for p in sorted(Path(json_dir).glob("*.json"))]
    return sorted(items, key=lambda it: (it[1]["eyestereo"].get("order", 100), it[0]))


def document(items: list[tuple[str, dict]], svg_rel: str) -> str:
    out = ["# Timing diagrams", "",
           "Every handshake of the library, drawn twice: the ASCII diagram from the interface's or block's "
           "docstring (what `help()` shows) and the same timing as a WaveDrom picture. Written by "
           "`make timing` (`eyestereo.hdl.flow.timing`) from `docs/wavedrom/*.json`; edit those and the docstrings, "
           "not this file.", "",
           "Signals are sampled on the rising clock edge; `#` high, `_` low, `.` don't care in the ASCII "
           "diagrams.", ""]
    for stem, d in items:
        meta = d["eyestereo"]
        text, where = ascii_for(meta)
        out += [f"## {meta['title']}", ""]
        if meta.get("defined_by"):
            out += [f"Defined by: {meta['defined_by']}.", ""]
        out += [f"ASCII ({where}):", "", "```", text, "```", "",
                f"![{meta['title']}]({svg_rel}/{stem}.svg)", "",
                f"Source: `docs/wavedrom/{stem}.json`.", ""]
    missing = [(k, v) for k, v in EXPECTED.items() if k not in {s for s, _ in items}]
    if missing:
        out += ["## Not yet available", ""]
        out += [f"* {v}: no diagram yet (add `docs/wavedrom/{k}.json`)." for k, v in missing]
        out.append("")
    return "\n".join(out)


def _write(path: Path, text: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(path.suffix + ".tmp")
    tmp.write_text(text)
    os.replace(tmp, path)


def build(json_dir: Path = JSON_DIR, svg_dir: Path = SVG_DIR, doc: Path = DOC) -> list[Path]:
    """Render every diagram and write the document; returns the files written. Nothing is written when
    any diagram fails."""
    items = diagrams(json_dir)
    svgs = {stem: render(d) for stem, d in items}
    text = document(items, os.path.relpath(svg_dir, Path(doc).parent))
    written = []
    for stem, svg in svgs.items():
        p = Path(svg_dir) / f"{stem}.svg"
        _write(p, svg)
        written.append(p)
    _write(Path(doc), text)
    return written + [Path(doc)]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description="Render the WaveDrom timing diagrams and write docs/timing.md.")
    ap.add_argument("--json-dir", type=Path, default=JSON_DIR)
    ap.add_argument("--svg-dir", type=Path, default=SVG_DIR)
    ap.add_argument("--doc", type=Path, default=DOC)
    args = ap.parse_args(argv)
    try:
        files = build(args.json_dir, args.svg_dir, args.doc)
    except (TimingError, ImportError) as e:
        print(f"make timing: {e}", file=sys.stderr)
        return 1
    for f in files:
        print(f)
    return 0


if __name__ == "__main__":
    sys.exit(main())
