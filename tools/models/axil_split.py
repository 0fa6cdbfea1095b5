"""Model of :func:`eyestereo.hdl.axi.axil_split.axil_split`: which slave each access reaches, with which
address, in which order, and what the master gets back.

The order: the split serves one master's two lines (its writes and its reads) one transaction at a time
by the arbiter's rule for a single master (:func:`eyestereo.tools.models.axil_arbiter.grant_order` with
``masters=1``: the kind not served last when both wait, a write first after reset). Each access goes to
slave ``(addr >> split_bit) & 1`` with bit ``split_bit`` cleared and the address cut to that slave's
``addr_bits``; everything else passes unchanged, the slave's response too.
"""

from __future__ import annotations

from dataclasses import replace

from eyestereo.tools.models.axil_arbiter import Access, Grant, WordMemory, grant_order

__all__ = ["route", "serve", "split_order"]


def route(a: Access, split_bit: int, slave_bits: tuple[int, int]) -> tuple[int, Access]:
    """(slave 0 or 1, the access as that slave sees it)."""
    port = a.addr >> split_bit & 1
    addr = a.addr & ~(1 << split_bit) & ((1 << slave_bits[port]) - 1)
    return port, replace(a, addr=addr)


def split_order(arrivals: dict, done: dict) -> list[Grant]:
    """The served order: ``arrivals``/``done`` keyed by ``write`` (True, False) as the arbiter's by line."""
    return grant_order({(0, w): v for w, v in arrivals.items()}, {(0, w): v for w, v in done.items()}, masters=1)


def serve(order: list[Grant], requests: dict, split_bit: int, slave_bits: tuple[int, int],
          slaves: tuple[WordMemory, WordMemory]) -> tuple[list[list[Access]], dict]:
    """Each slave's accesses in order and the master's answers: ``requests[write]`` are the master's writes
    and reads; returns (``[accesses of s0, accesses of s1]``, ``{write: [(resp, data), ...]}``)."""
    seen, answers = [[], []], {True: [], False: []}
    for g in order:
        port, a = route(requests[g.write][g.index], split_bit, slave_bits)
        seen[port].append(a)
        answers[g.write].append(slaves[port].access(a))
    return seen, answers
