"""Clock-accurate model of :func:`eyestereo.hdl.streaming.async_fifo.async_fifo`: the frames it passes and drops.

The FIFO's behaviour depends on when words arrive, when the reader takes them and when each side sees the
other's pointer through its two-flop synchroniser. The model knows both clocks (period and phase in ps),
the write edges of the input beats, the reader's stall windows (``ready`` low) and the per-domain resets,
and follows the block's rules edge by edge (it jumps from event to event, so a frame of 100,000 words costs
a fraction of a second):

Write side (write clock, per edge):

* ``full`` when ``depth`` entries are written and not yet seen read: a read at read-clock edge ``p`` is
  seen from write edge ``b + 2`` on, where ``b`` is the first write edge after ``p`` (the synchroniser's
  first flop takes it there, the second one edge later, and ``full`` is decided from the second).
* a pixel beat of a good frame is written unless ``full`` or a reset token is pending; then it is lost:
  the frame becomes *bad* (its later beats are discarded up to its ``eof``), the dropped-frame counter
  counts it, and if words of it are in the FIFO a reset token is made pending.
* a reset token from the source aborts a frame that has begun: counted; a token follows it into the FIFO
  (pending if the FIFO is full) when words of it are there.
* a pending token is written at the first edge (after the one that made it pending) at which the FIFO
  is not full; a pixel beat in that edge is lost.
* reset (``wrst`` high): a frame that has begun is abandoned (counted, a token pending if words of it are
  in the FIFO); beats during reset are ignored. Pointers are never reset.

Read side (read clock, per edge): an entry written at write edge ``k`` can be loaded into the output
register from read edge ``a + 2`` on, where ``a`` is the first read edge after ``k``; it is loaded when
the output register is empty or being emptied in that edge; it is presented (``valid``) and taken at the
first later edge with ``ready`` high. After a reset of the read side (``rrst``) that found the reader in
the middle of a frame, entries are loaded and discarded until one with ``eof`` (end of that frame, or a
token) has gone; a word held in the output register at the reset is discarded.

Edge-exact is the intent; where two edges of the two clocks coincide in time the real circuit may go either
way, and :func:`eyestereo.tools.models.camera_interface.camera_interface` checks that the frame-level
outcome does not depend on it (by moving each synchroniser by one edge either way).
"""

from __future__ import annotations

import bisect
from dataclasses import dataclass, field

__all__ = ["ClockSpec", "Entry", "FifoResult", "async_fifo", "TOKEN_DATA"]

TOKEN_DATA = 0


@dataclass(frozen=True)
class ClockSpec:
    """A clock: ``period`` and the time of edge 0 (``phase``), both in ps; edge k at phase + k * period."""

    period: int
    phase: int = 0

    def __post_init__(self):
        if self.period <= 0 or self.phase < 0:
            raise ValueError(f"ClockSpec needs period > 0 and phase >= 0 ps, got {self.period}, {self.phase}")

    def time(self, k: int) -> int:
        return self.phase + k * self.period

    def first_after(self, t: int) -> int:
        """Index of the first edge strictly later than time ``t``."""
        if t < self.phase:
            return 0
        return (t - self.phase) // self.period + 1

    @property
    def mhz(self) -> float:
        return 1e6 / self.period


@dataclass(slots=True)
class Entry:
    """One FIFO entry: a word or a token, its write edge, and what became of it on the read side."""

    data: int
    eol: bool
    eof: bool
    tag: int
    wedge: int
    pop: int | None = None  # read edge at which it was loaded into the output register
    leave: int | None = None  # read edge at which it left the output register
    taken: bool = False  # taken by the reader (else discarded after a read-side reset)

    @property
    def token(self) -> bool:
        return self.eof and not self.eol


@dataclass
class FifoResult:
    out: list[Entry]  # entries taken by the reader, in order
    entries: list[Entry]  # every entry written
    dropped: int  # the dropped-frame counter
    lost: int  # pixel beats lost (not written) on the write side
    max_level: int  # most entries in the FIFO (written, not yet seen read by the writer)
    last_edge: int  # read edge of the last event (take or discard), -1 if none
    rresets: list[tuple[int, int]] = field(default_factory=list)  # read-side reset intervals applied

    def segments(self):
        """The taken words split where the reader's consumer starts over: yields (kind, tag, words)
        with kind "frame" (ends with eof), "token" (a reset token after ``words``) or "reset" (a
        read-side reset cut ``words`` off)."""
        cur: list[int] = []
        tag, prev = None, -1
        for e in self.out:
            if cur and any(prev < a <= e.leave for a, _ in self.rresets):
                yield "reset", tag, cur
                cur = []
            prev = e.leave
            if e.token:
                yield "token", e.tag, cur
                cur = []
                continue
            cur.append(e.data)
            tag = e.tag
            if e.eof:
                yield "frame", e.tag, cur
                cur = []


def _intervals(iv) -> list[tuple[int, int]]:
    out = []
    for a, b in iv:
        a, b = int(a), int(b)
        if b <= a:
            raise ValueError(f"interval ({a}, {b}) is empty")
        out.append((a, b))
    return sorted(out)


def _outside(e: int, intervals) -> int:
    """The first edge >= e outside every ``(first, end)`` interval (they may touch or overlap)."""
    moved = True
    while moved:
        moved = False
        for a, b in intervals:
            if a <= e < b:
                e, moved = b, True
    return e


class _Reader:
    def __init__(self, rclk: ClockSpec, resets, stalls, r_sync: int):
        self.clk = rclk
        self.resets = resets
        self.stalls = stalls
        self.r_sync = r_sync
        self.applied = 0  # resets[:applied] have acted on the reader's skip state
        self.free = 0
        self.skip = False
        self.last_eof = True
        self.last_edge = -1

    def push(self, entry: Entry, wclk: ClockSpec) -> None:
        a = self.clk.first_after(wclk.time(entry.wedge))
        p = max(a + self.r_sync, self.free)
        while True:
            # read-side resets that begin while the output register is empty act on the skip state
            while self.applied < len(self.resets) and self.resets[self.applied][0] <= p:
                self.skip = not self.last_eof
                self.applied += 1
            q = _outside(p, self.resets)
            if q == p:
                break
            p = q
        entry.pop = p
        nxt = self.resets[self.applied][0] if self.applied < len(self.resets) else None
        if self.skip:
            leave = p + 1
            if nxt is not None and nxt <= leave:
                self.applied += 1
            entry.leave, entry.taken = leave, False
            self.skip = not entry.eof
        else:
            take = _outside(p + 1, self.stalls)
            if nxt is not None and nxt <= take:
                entry.leave, entry.taken = nxt, False
                self.applied += 1
                self.skip = not entry.eof
            else:
                entry.leave, entry.taken = take, True
        self.last_eof = entry.eof
        self.free = entry.leave
        self.last_edge = max(self.last_edge, entry.leave)


def async_fifo(beats, *, depth: int, wclk: ClockSpec, rclk: ClockSpec, wresets=(), rresets=(), stalls=(),
               w_sync: int = 2, r_sync: int = 2) -> FifoResult:
    """Run the FIFO on input beats.

    Args:
        beats: ``(data, eol, eof, edge, tag)`` tuples (or objects with those attributes) in edge order;
            ``edge`` is the write-clock edge at which the FIFO samples the beat, ``tag`` any label (the
            camera frame index) that the model carries along.
        depth: entries of the FIFO memory.
        wclk, rclk: the two clocks.
        wresets, rresets: ``[(first, end), ...]`` edge intervals (of the own clock) with the reset high.
        stalls: read-clock edge intervals with ``ready`` low.
        w_sync, r_sync: synchroniser depth as seen by the rules above (2: two flops). The consistency
            check varies them by one.
    """
    wres = _intervals(wresets)
    reader = _Reader(rclk, _intervals(rresets), _intervals(stalls), r_sync)
    entries: list[Entry] = []
    vis: list[int] = []  # write edge from which each entry's read is seen by the writer
    st = dict(started=False, bad=False, mid=False, tok=False, tok_edge=0, tok_tag=0, count=0, lost=0,
              seen=0, max_level=0, tag=None)

    def write(data, eol, eof, tag, k):
        e = Entry(int(data), bool(eol), bool(eof), tag, k)
        reader.push(e, wclk)
        entries.append(e)
        vis.append(wclk.first_after(rclk.time(e.pop)) + w_sync)

    def level(k):
        while st["seen"] < len(entries) and vis[st["seen"]] <= k:
            st["seen"] += 1
        return len(entries) - st["seen"]

    def full(k):
        lv = level(k)
        st["max_level"] = max(st["max_level"], lv)
        return lv >= depth

    def in_wreset(k):
        i = bisect.bisect_right(wres, (k, float("inf"))) - 1
        return i >= 0 and wres[i][0] <= k < wres[i][1]

    def token_edge():
        """Earliest edge after the one that made the token pending at which it can be written."""
        k = st["tok_edge"] + 1
        idx = len(entries) - depth
        if idx >= 0:
            k = max(k, vis[idx])
        return _outside(k, wres)

    def reset_edge(k):
        if st["started"] and not st["bad"]:
            st["count"] += 1
        if st["mid"]:
            st["tok"], st["tok_edge"], st["tok_tag"] = True, k, st["tag"]
        st.update(started=False, bad=False, mid=False)

    def make_pending(k):
        st["tok"], st["tok_edge"], st["tok_tag"] = True, k, st["tag"]

    def beat(data, eol, eof, k, tag):
        tok_now = False
        if st["tok"]:
            kt = token_edge()
            if kt <= k:
                write(TOKEN_DATA, False, True, st["tok_tag"], kt)
                st["tok"] = False
                tok_now = kt == k
        is_tok = eof and not eol
        if not is_tok:
            if st["bad"]:
                if eof:
                    st.update(bad=False, started=False)
            elif tok_now or st["tok"] or full(k):
                st["count"] += 1
                st["lost"] += 1
                if st["mid"]:
                    make_pending(k)
                st.update(mid=False, bad=not eof, started=not eof, tag=tag)
            else:
                write(data, eol, eof, tag, k)
                st.update(mid=not eof, started=not eof, tag=tag)
        else:
            if st["bad"]:
                st["bad"] = False
            elif st["started"]:
                st["count"] += 1
                if st["mid"]:
                    if tok_now or st["tok"] or full(k):
                        make_pending(k)
                    else:
                        write(TOKEN_DATA, False, True, st["tag"], k)
                st["mid"] = False
            st["started"] = False

    def write_token(before=float("inf")):
        """The pending token, if any, written if it can be before edge ``before``."""
        if st["tok"] and token_edge() < before:
            write(TOKEN_DATA, False, True, st["tok_tag"], token_edge())
            st["tok"] = False

    resets = iter(first for first, _ in wres)
    ra = next(resets, None)

    def resets_up_to(k):
        """The resets that begin at or before edge ``k`` (a pending token may be written before each)."""
        nonlocal ra
        while ra is not None and ra <= k:
            write_token(ra)
            reset_edge(ra)
            ra = next(resets, None)

    for b in beats:
        data, eol, eof, k, tag = (b if isinstance(b, tuple) else (b.data, b.eol, b.eof, b.edge, b.frame))
        resets_up_to(k)
        if not in_wreset(k):
            beat(data, eol, eof, k, tag)
    resets_up_to(float("inf"))
    write_token()
    # the level seen by the writer, up to the last write
    if entries:
        full(entries[-1].wedge)
    out = [e for e in entries if e.taken]
    return FifoResult(out=out, entries=entries, dropped=st["count"], lost=st["lost"],
                      max_level=st["max_level"], last_edge=reader.last_edge, rresets=reader.resets)
