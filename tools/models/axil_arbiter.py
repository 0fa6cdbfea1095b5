"""Model of :func:`eyestereo.hdl.axi.axil_arbiter.axil_arbiter`: the grant order under its round-robin rule, what
the slave sees and what each master's reads return.

Clocks are counted in rising edges. A *line* is one master's writes or its reads, ``(master, write)``;
each line's requests are served in their order (AXI4-Lite keeps a channel's order). Given when each
request arrived (the edge at which its ``awvalid``/``arvalid`` was first sampled high) and when each
transaction ended (the edge at which its B or R moved on the master's port: the slave's and the
master's timing, which the arbiter does not choose), :func:`grant_order` gives the grants in order and
the edge at which each grant's address moves on the master's port, by the block's rule:

* the arbiter decides at the first edge ``d`` at which it is idle and a request has arrived (idle from
  the first edge, and again from the edge after a transaction ended);
* among the masters with a request at ``d``: the first after the master granted last (round robin;
  master 0 first after reset); of that master's two lines the kind it was not granted last when both
  wait (a write first after reset);
* the granted address moves at ``d + 1``.

:func:`waits` measures, per granted request, what it waited for; :class:`WordMemory` is the slave's
memory (32-bit words, byte strobes, an optional error code per address) that gives every read's data.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

__all__ = ["Access", "Grant", "Wait", "WordMemory", "grant_order", "passed_over", "replay", "waits"]

OKAY, SLVERR, DECERR = 0, 2, 3


@dataclass(frozen=True)
class Access:
    """One AXI4-Lite access as a port carries it: a write (address, data word, byte strobes) or a read."""

    write: bool
    addr: int
    prot: int = 0
    data: int = 0
    strb: int = 0xF


@dataclass(frozen=True)
class Grant:
    """A granted request: the ``index``-th of line ``(master, write)``; its address moves at edge ``accept``."""

    master: int
    write: bool
    index: int
    accept: int

    @property
    def line(self) -> tuple[int, bool]:
        return self.master, self.write


@dataclass(frozen=True)
class Wait:
    """What one request waited for between its arrival and its grant: grants to other masters, grants
    of its own master's other line, and clocks (edges from arrival to the decision)."""

    others: int
    own: int
    clocks: int


def grant_order(arrivals: dict, done: dict, *, masters: int = 2) -> list[Grant]:
    """The grants in order (module docstring). ``arrivals[(m, w)]``: the arrival edges of line ``(m, w)``'s
    requests in order; ``done[(m, w)]``: the edge at which each one's response moved on the master's port
    (at least as many entries as grants of the line, else a ValueError)."""
    lines = [(m, w) for m in range(masters) for w in (True, False)]
    head = dict.fromkeys(lines, 0)
    last, last_w = masters - 1, [False] * masters
    free, grants = 0, []
    while True:
        waiting = [ln for ln in lines if head[ln] < len(arrivals.get(ln, ()))]
        if not waiting:
            return grants
        d = max(free, min(arrivals[ln][head[ln]] for ln in waiting))
        pending = {ln for ln in waiting if arrivals[ln][head[ln]] <= d}
        pick = next(m for m in ((last + 1 + i) % masters for i in range(masters))
                    if (m, True) in pending or (m, False) in pending)
        wr = (pick, True) in pending and ((pick, False) not in pending or not last_w[pick])
        last, last_w[pick] = pick, wr
        line = (pick, wr)
        k = head[line]
        head[line] += 1
        grants.append(Grant(pick, wr, k, d + 1))
        ends = done.get(line, ())
        if k >= len(ends):
            raise ValueError(f"no end given for request {k} of line {line}")
        if ends[k] <= d + 1:
            raise ValueError(f"request {k} of line {line} ends at edge {ends[k]}, not after its grant at {d + 1}")
        free = ends[k] + 1


def waits(grants: list[Grant], arrivals: dict) -> list[Wait]:
    """Per grant (in order): what its request waited for between its arrival and its decision edge."""
    out = []
    for g in grants:
        a, d = arrivals[g.line][g.index], g.accept - 1
        between = [h for h in grants if a <= h.accept - 1 < d]
        out.append(Wait(others=sum(h.master != g.master for h in between),
                        own=sum(h.master == g.master and h.write != g.write for h in between), clocks=d - a))
    return out



def passed_over(grants: list[Grant], arrivals: dict, *, masters: int = 2) -> tuple[list[int], int]:
    """(per master: the most decisions in a row it lost while a request of its waited, the number of
    decisions at which another master than the one granted waited too). The round-robin rule keeps the
    first at most 1 for two masters."""
    decided = {(g.line, g.index): g.accept - 1 for g in grants}
    run, worst, contended = [0] * masters, [0] * masters, 0
    for g in grants:
        d = g.accept - 1
        others = False
        for m in range(masters):
            waiting = m != g.master and any(a <= d < decided.get(((m, w), k), d) for w in (True, False)
                                            for k, a in enumerate(arrivals.get((m, w), ())))
            run[m] = run[m] + 1 if waiting else 0
            worst[m] = max(worst[m], run[m])
            others = others or waiting
        contended += others
    return worst, contended

class WordMemory:
    """A slave's memory of 32-bit words at byte addresses ``addr & ~3`` (``size`` bytes, wrapping), 0 at
    first; ``code(addr)`` gives the response of an access (OKAY = 0 by default); an access answered
    with an error code changes nothing and reads 0."""

    def __init__(self, size: int, code: Callable[[int], int] | None = None):
        self.size, self.words = int(size), {}
        self.code = code or (lambda addr: OKAY)

    def access(self, a: Access) -> tuple[int, int]:
        """(response code, read data) of an access (writes: data 0)."""
        resp = self.code(a.addr)
        word = (a.addr % self.size) & ~3
        if resp != OKAY:
            return resp, 0
        if not a.write:
            return OKAY, self.words.get(word, 0)
        old = self.words.get(word, 0)
        mask = sum(0xFF << 8 * i for i in range(4) if a.strb >> i & 1)
        self.words[word] = (old & ~mask | a.data & mask) & 0xFFFFFFFF
        return OKAY, 0


def replay(grants: list[Grant], requests: dict, memory: WordMemory) -> tuple[list[Access], dict]:
    """What the slave sees, in order, and every request's answer: ``requests[(m, w)]`` are the lines'
    accesses; returns (the accesses in grant order, ``{(m, w): [(resp, data), ...]}``)."""
    seen, answers = [], {ln: [] for ln in requests}
    for g in grants:
        a = requests[g.line][g.index]
        seen.append(a)
        answers[g.line].append(memory.access(a))
    return seen, answers
