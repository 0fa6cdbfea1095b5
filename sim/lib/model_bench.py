"""A block bench made from nothing but its model function.

The smallest stream blocks (no control ports, no configuration beyond their hardware parameters) are
checked the same way: each input frame through the block, its output against the bit-true model's output
for that frame. :func:`model_bench` builds that bench, so such a bench module is one statement::

    LineDelayTB, line_delay_frames = model_bench("line_delay", model.line_delay, module=__name__)

(the class for the benches that reuse it by name, e.g. ``tb_recovery``; the cocotb test). Blocks with
control ports or configured behaviour subclass :class:`eyestereo.sim.lib.bench.StreamTB` instead.
"""

from __future__ import annotations

from collections.abc import Callable

import cocotb
import numpy as np

from eyestereo.sim.lib.bench import StreamTB, run_configured

Expected = Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]


def model_bench(block: str, expected: Expected, *, module: str, token_spec: str = StreamTB.token_spec):
    """(the bench class ``<Block>TB``, the cocotb test ``<block>_frames``) of the bench module ``module``.

    Assign both to module attributes: cocotb finds a test among the attributes of the module it runs and
    names it after the function's module and name, which this sets.

    Parameters:
        block: the block's name, in snake case; the class is its camel case + ``TB``.
        expected: the model: an input frame -> (expected output words, mask of the pixels whose data is
            specified).
        module: the bench module's name (pass ``__name__``).
        token_spec: stimulus of the partial frame cut by the reset token (:func:`eyestereo.sim.lib.bench.make_frame`).
    """

    class ModelTB(StreamTB):
        def expected(self, frame: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            return expected(frame)

    ModelTB.token_spec = token_spec
    ModelTB.__name__ = ModelTB.__qualname__ = "".join(w.capitalize() for w in block.split("_")) + "TB"
    ModelTB.__module__ = module

    async def frames(dut) -> None:
        report = await run_configured(dut, ModelTB)
        assert report["pixels_compared"] > 0

    frames.__name__ = frames.__qualname__ = f"{block}_frames"
    frames.__module__ = module
    return ModelTB, cocotb.test(frames)
