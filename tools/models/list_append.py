"""Bit-true model of the ``list_append`` block (issue 29): a frame's feature list, filler, then its match list.

The front end's matcher option writes a frame's match list into the frame's feature-list buffer from a fixed
word (:func:`eyestereo.tools.models.sram_arbiter.match_offset`), so the host reads the matches without the
features. This model gives the queue words the block sends for a sequence of frames.
"""

from __future__ import annotations

__all__ = ["list_append"]


def list_append(frames, offset: int) -> list[tuple[int, bool, bool]]:
    """The words ``(data, eol, eof)`` out for ``frames``: a list of (feature words, match words), each a list of
    ``(data, eol, eof)`` as the feature list and the matcher send them (a feature list either ends with its trailer,
    ``eol`` and ``eof`` on the last word, or is aborted by a reset token, ``eof`` without ``eol``).

    A whole feature list goes out with its last word's ``eof`` dropped, then words of 0 up to ``offset`` words, then
    the match list as it is. An aborted feature list goes out up to and with its token, and that frame's match list
    is dropped."""
    out = []
    for feats, matches in frames:
        for d, eol, eof in feats:
            if eof and not eol:  # a token: the list aborted, the frame's matches dropped
                out.append((d, eol, eof))
                break
            out.append((d, eol, False))
        else:
            out += [(0, False, False)] * max(0, offset - len(feats))
            out += list(matches)
    return out
