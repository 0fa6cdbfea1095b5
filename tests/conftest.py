import pytest


def pytest_collection_modifyitems(config, items):
    # The GHDL benches are the slow part: start them first so the 2 workers finish together.
    items.sort(key=lambda it: 0 if it.get_closest_marker("sim") else 1)
