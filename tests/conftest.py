import pytest


def pytest_collection_modifyitems(config, items):
    # The Icarus/Verilator regressions of every bench (marker othersims) are long: only when -m names them
    # (make test-sims); make test runs the VHDL benches on GHDL and the small three-simulator comparison.
    if "othersims" not in (config.getoption("-m") or ""):
        keep = [it for it in items if not it.get_closest_marker("othersims")]
        if len(keep) != len(items):
            config.hook.pytest_deselected(items=[it for it in items if it.get_closest_marker("othersims")])
            items[:] = keep
    # The GHDL benches are the slow part: start them first so the 2 workers finish together.
    items.sort(key=lambda it: 0 if (it.get_closest_marker("sim") or it.get_closest_marker("othersims")) else 1)
