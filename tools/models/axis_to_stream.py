"""Bit-true model of :func:`eyestereo.hdl.axi.axis_to_stream.axis_to_stream`: AXI4-Stream video -> image stream.

The block counts transfers into ``width`` x ``height`` frames; the model applies the same rules to a list
of AXI beats ``(tdata, tlast, tuser)`` and returns the image-stream beats ``(data, eol, eof)`` (reset
token: ``(0, False, True)``) and the number of ``error`` pulses. The rules (the block's docstring):

* ``tuser`` inside a frame: reset token, error, and the SOF pixel starts the next frame;
* ``tlast`` missing on pixel ``width - 1`` or present on an earlier pixel: reset token, error, and
  everything up to the next SOF is dropped;
* a transfer outside a frame without ``tuser``: dropped; the first one after a completed frame counts
  one error (the frame had too many lines), those before the first SOF after reset or after a faulty
  line count none.
"""

from __future__ import annotations

from eyestereo.tools.stream import TOKEN, Beat

AxisBeat = tuple[int, bool, bool]


def axis_to_stream(beats: list[AxisBeat], width: int, height: int) -> tuple[list[Beat], int]:
    """(image-stream beats, error pulses) for a sequence of AXI4-Stream video beats."""
    out: list[Beat] = []
    errors = 0
    x = y = 0
    in_frame = synced = False
    for data, last, user in beats:
        data, last, user = int(data), bool(last), bool(user)
        if user and in_frame:
            out.append(TOKEN)
            errors += 1
            in_frame = False
            synced = True
            x = y = 0
        if user or in_frame:
            if user:
                synced = True
                x = y = 0
            at_end = x == width - 1
            if last != at_end:
                out.append(TOKEN)
                errors += 1
                in_frame = synced = False
                continue
            end = at_end and y == height - 1
            out.append((data, at_end, end))
            in_frame = not end
            if at_end:
                x, y = 0, (0 if end else y + 1)
            else:
                x += 1
        elif synced:
            errors += 1
            synced = False
    return out, errors
