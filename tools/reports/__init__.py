"""Benchmark and report scripts that write the measured pages in ``docs/``."""

from __future__ import annotations

import os
import sys
from collections.abc import Iterable, Sequence
from pathlib import Path

from eyestereo.tools.io import atomic_write_text, write_section


def publish(text: str, doc: str | os.PathLike[str] | None, begin: str | None = None, end: str | None = None) -> None:
    """Print a report and, unless ``doc`` is None, write it: into the ``begin`` ... ``end`` section of the
    page ``doc`` (:func:`eyestereo.tools.io.write_section`), or without markers as the whole page (its
    folder made if missing). The last step of every measurement script."""
    sys.stdout.write(text)
    if doc is None:
        return
    if begin is None or end is None:
        Path(doc).parent.mkdir(parents=True, exist_ok=True)
        atomic_write_text(doc, text)
    else:
        write_section(doc, text, begin, end)
    print(f"written to {doc}")


def markdown_table(header: Sequence[object], rows: Iterable[Sequence[object]], align: str | None = None) -> list[str]:
    """The lines of a Markdown table: the ``header`` row, the alignment row, one line per row of ``rows``.

    Cells are written with ``str``; an empty cell is a single space (``| |``). ``align`` has one letter per
    column, ``l`` (left) or ``r`` (right); by default the first column is left-aligned and the others, the
    numbers of most measured pages, right-aligned."""
    align = align or "l" + "r" * (len(header) - 1)
    if len(align) != len(header) or set(align) - {"l", "r"}:
        raise ValueError(f"align {align!r}: one 'l' or 'r' per column of the {len(header)} in the header")

    def line(cells: Sequence[object]) -> str:
        return "|" + "|".join(f" {c} " if str(c) else " " for c in cells) + "|"

    return [line(header), "|" + "|".join("---" if a == "l" else "---:" for a in align) + "|"] + [line(r) for r in rows]
