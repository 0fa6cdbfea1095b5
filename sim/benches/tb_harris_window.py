"""cocotb bench: harris_window against :func:`eyestereo.tools.models.harris_window.harris_window`, bit for bit."""

from eyestereo.sim.lib.model_bench import model_bench
from eyestereo.tools.models import harris_window as model

HarrisWindowTB, harris_window_frames = model_bench("harris_window", model.harris_window, module=__name__,
                                                   token_spec="grad:99:128")
