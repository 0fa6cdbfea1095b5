"""sim/apps/steps.py: one printed line per step, the step's own output (child processes too) in its log."""

from __future__ import annotations

import io
import subprocess
import sys

import pytest

from eyestereo.sim.apps.steps import StepFailed, StepRunner


def test_each_step_prints_one_line_and_logs_the_rest(tmp_path):
    screen = io.StringIO()
    steps = StepRunner(tmp_path / "logs", stream=screen)

    def noisy():
        print("simulator banner\n" * 50)
        print("warning from python", file=sys.stderr)
        child = "import sys; print('child says hi'); print('child err', file=sys.stderr)"
        subprocess.run([sys.executable, "-c", child], check=True)
        return 42, "1234 pixels bit-exact -> a.png"

    assert steps.run("sobel", noisy) == 42
    assert steps.run("plain", lambda: "done") == "done"
    lines = screen.getvalue().splitlines()
    assert len(lines) == 2 and lines[0].startswith("sobel ") and "1234 pixels bit-exact -> a.png" in lines[0]
    log = (tmp_path / "logs" / "sobel.log").read_text()
    assert "simulator banner" in log and "warning from python" in log and "child says hi" in log and "child err" in log
    with pytest.raises(StepFailed):
        steps.run("broken step", lambda: 1 / 0)
    assert steps.run("later", lambda: 1 / 0, stop_on_failure=False) is None
    last = screen.getvalue().splitlines()[-2:]
    assert "FAILED: division by zero" in last[0] and "broken_step.log" in last[0]
    assert steps.finish() == 1 and steps.failed == ["broken step", "later"]
