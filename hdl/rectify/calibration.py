"""The calibration of the rectification blocks, resolved in one place.

A rectify block's parameters name their calibration as ``quantizers`` (a spec of
:func:`eyestereo.tools.rectify.calibrations.load` such as ``"rig"`` or ``"seed:3:2@40x20"``, a
``quantizers.json`` path or document, or a :class:`~eyestereo.tools.models.poly_unit.Calibration`) and
``source_width``/``source_height`` (the camera images; default the document's). :func:`calibration_param`
turns them into the checked :class:`~eyestereo.tools.models.poly_unit.Calibration`; the blocks
(poly_unit, coordinate_warper, rectifier, stereo_frontend), the catalogue's port builders, the bench
harness and the cocotb benches all call it (the benches through :func:`calibration_of` on the
parameters the runner hands them), so the conversion and the bench check against the same calibration.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from typing import Any

from eyestereo.hdl.common.checks import block_error, check_int
from eyestereo.tools.models.poly_unit import Calibration
from eyestereo.tools.rectify.ffc import FFCError

__all__ = ["calibration_of", "calibration_param"]


def calibration_param(quantizers: Any, source_width: Any = None, source_height: Any = None) -> Calibration:
    """The ``quantizers`` parameter (a :class:`~eyestereo.tools.models.poly_unit.Calibration`, a spec of
    :func:`eyestereo.tools.rectify.calibrations.load`, a path or a document; None: the default spec) with
    the camera image size, as a checked calibration (a ValueError naming the block and the parameter)."""
    sw = None if source_width is None else check_int("source_width", source_width, 2, 65536)
    sh = None if source_height is None else check_int("source_height", source_height, 2, 65536)
    if isinstance(quantizers, Calibration):
        cal = quantizers
        if sw is not None or sh is not None:
            cal = Calibration(cal.width, cal.height, sw or cal.source_width, sh or cal.source_height,
                              cal.formats, cal.codes, cal.origin)
    else:
        if quantizers is not None and not isinstance(quantizers, (str, os.PathLike, dict)):
            raise block_error(f"parameter quantizers must be a calibration spec, a quantizers.json path or "
                              f"document, or a Calibration; got {type(quantizers).__name__}")
        try:
            cal = Calibration.load(quantizers, source_width=sw, source_height=sh)
        except (FFCError, ValueError, FileNotFoundError, KeyError) as exc:
            raise block_error(f"parameter quantizers: {exc}") from None
    if cal.source_width < 2 or cal.source_height < 2:
        raise block_error(f"parameter source_width/source_height: the camera image must be at least 2x2 "
                          f"pixels, got {cal.source_width}x{cal.source_height}")
    for i, f in enumerate(cal.formats[:10], 1):
        if f.wl > 31:
            raise block_error(f"parameter quantizers: q{i} {f} is wider than 31 bits (VHDL integer constants)")
    if cal.out_format.wl > 31:
        raise block_error(f"parameter quantizers: q24 {cal.out_format} is wider than 31 bits")
    return cal


def calibration_of(params: Mapping[str, Any]) -> Calibration:
    """:func:`calibration_param` of a rectify block's parameters (a catalogue configuration or the
    ``params`` a bench gets; missing keys take the blocks' defaults)."""
    return calibration_param(params.get("quantizers"), params.get("source_width"), params.get("source_height"))
