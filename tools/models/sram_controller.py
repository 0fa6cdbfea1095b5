"""Cycle-true model of :func:`eyestereo.hdl.memory.sram_controller.sram_controller`: which clocks it takes a command
in, and in which clock each read's data comes back (pure Python).

The controller's data behaviour is the part's (a read returns the last word written, see
:mod:`eyestereo.tools.sram`); what is particular to the controller is its timing, modelled here:

* a read is always taken; a write on a NoBL part too;
* on a pipelined SyncBurst part a write offered in the clock that ends with edge ``e`` is held off while
  a read was taken at an edge ``e - d`` with ``d`` in :func:`write_block_window` (the part drives that
  read's data in a cycle too close to the write's data cycle);
* the read taken at the end of clock ``c`` (clocks counted from 0) comes back in clock
  ``c + read_latency + 2``.
"""

from __future__ import annotations

from dataclasses import dataclass

from eyestereo.tools.sram import KINDS

__all__ = ["write_block_window", "latency", "Command", "schedule"]


def write_block_window(kind: str, read_latency: int) -> tuple[int, int]:
    """(lo, hi): a write waits while a read was taken ``lo..hi`` clocks before it (empty when lo > hi).

    Pipelined SyncBurst: the read taken ``d`` clocks before drives the bus ``read_latency - d`` cycles after
    the write's own data cycle; the part wants one idle cycle between the two in either order, so
    ``|read_latency - d| >= 2``: ``d`` in ``[read_latency - 1, read_latency + 1]`` (and ``d >= 1``).
    NoBL: nothing to wait for.
    """
    if kind not in KINDS:
        raise ValueError(f"SRAM kind must be one of {KINDS}, got {kind!r}")
    if kind == "nobl":
        return 1, 0
    return max(1, read_latency - 1), read_latency + 1


def latency(read_latency: int) -> int:
    """Clocks from a read's command to its response (the controller's documented latency)."""
    return read_latency + 2


@dataclass
class Command:
    """A command for the word port; ``gap`` idle clocks are left before it is offered (then held until taken)."""

    we: bool
    addr: int = 0
    data: int = 0
    be: int = 3
    tag: int = 0
    gap: int = 0


def schedule(commands: list[Command], kind: str, read_latency: int, *, start: int = 0) -> tuple[list[int], list[int]]:
    """Offer ``commands`` in order from clock ``start``, each after its ``gap`` and held until taken.

    Returns (the clock each command is taken in, the clock each read's response appears in, in order).
    """
    lo, hi = write_block_window(kind, read_latency)
    taken: list[int] = []
    reads_at: list[int] = []
    c = start
    for cmd in commands:
        c += cmd.gap
        if cmd.we:
            while any((c - r) in range(lo, hi + 1) for r in reads_at[-4:]):
                c += 1
        taken.append(c)
        if not cmd.we:
            reads_at.append(c)
        c += 1
    responses = [r + latency(read_latency) for r in reads_at]
    return taken, responses
