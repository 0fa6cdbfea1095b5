"""The file formats and names of the fast harness's test models (:mod:`eyestereo.sim.harnesses.frontend_harness`).

Shared by the harness (which writes the models that read and write these files) and the benches' library
(:mod:`eyestereo.sim.lib.fast_system`, which writes the camera scripts and reads the SRAM dumps). Plain constants:
no simulator, no MyHDL.
"""

from __future__ import annotations

#: Camera script run kinds: a run's header is ``kind << RUN_SHIFT | n`` (one decimal integer per line).
RUN_KINDS = {"vsync": 1, "idle": 2, "line": 3, "stop": 4}
RUN_SHIFT = 24
#: The SRAM part's rules by number (its ``viol_rule``, the bits of ``viol_rules``).
SRAM_RULES = ("inputs defined", "single accesses only", "byte writes", "write data in the right cycle",
              "no bus contention", "output enable")
#: The SRAM part's backdoor dump, in the simulation's folder.
DUMP_FILE = "sram_dump.txt"
#: The camera players' scripts, in the simulation's folder.
SCRIPT_FILES = {"l": "cam_l.txt", "r": "cam_r.txt"}
