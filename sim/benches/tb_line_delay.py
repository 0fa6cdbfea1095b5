"""cocotb bench: line_delay against :func:`eyestereo.tools.models.line_delay.line_delay`, bit for bit."""

from eyestereo.sim.lib.model_bench import model_bench
from eyestereo.tools.models import line_delay as model

LineDelayTB, line_delay_frames = model_bench("line_delay", model.line_delay, module=__name__)
