"""Model of :func:`eyestereo.hdl.streaming.word_cdc.word_cdc`: what ``q`` may show, given what ``d`` was.

The block's contract (its docstring): every value ``q`` takes is a value ``d`` had, taken whole, in ``d``'s
order (so ``q``'s values are a subsequence of ``d``'s); each appears in ``q`` more than two destination
periods after ``d`` took it (the synchroniser's two flops and the load); and once ``d`` stops changing,
``q`` equals it within 6 destination + 4 source periods. :func:`check` tests recorded change
lists against that and returns the breaches.
"""

from __future__ import annotations

__all__ = ["check", "settle_time"]


def settle_time(s_period: float, d_period: float) -> float:
    """Longest time from ``d``'s last change to ``q`` equal to it."""
    return 6 * d_period + 4 * s_period


def check(d_changes, q_changes, *, s_period: float, d_period: float, end: float, q0: int = 0) -> list[str]:
    """Breaches of the contract. ``d_changes``/``q_changes``: ``[(time, value), ...]`` in time order (the
    first ``d`` entry is its value from time 0); ``end``: when the recording stopped."""
    errors = []
    seq = list(d_changes)
    i = 0  # index into d's history of the value q shows
    q = q0
    for t, v in q_changes:
        j = next((k for k in range(i, len(seq)) if seq[k][1] == v and seq[k][0] <= t - 2 * d_period), None)
        if j is None:
            errors.append(f"q = {v:#x} at {t}: not a value d had at least two destination clocks before, after "
                          f"{q:#x}")
            continue
        i, q = j, v
    last_t, last_v = seq[-1]
    if end - last_t >= settle_time(s_period, d_period) and q != last_v:
        errors.append(f"q = {q:#x} at the end, d = {last_v:#x} since {last_t} (more than "
                      f"{settle_time(s_period, d_period)} before the end)")
    return errors
