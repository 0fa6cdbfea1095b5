import pytest


@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(config, items):
    # The Icarus/Verilator regressions of every bench (marker othersims) are long: only when -m names them
    # (make test-sims); make test runs the VHDL benches on GHDL and the small three-simulator comparison.
    # First of the hooks: pytest-split's groups (make test GROUP=k/N) are taken from what is left.
    if "othersims" not in (config.getoption("-m") or ""):
        keep = [it for it in items if not it.get_closest_marker("othersims")]
        if len(keep) != len(items):
            config.hook.pytest_deselected(items=[it for it in items if it.get_closest_marker("othersims")])
            items[:] = keep


def pytest_configure(config):
    config.pluginmanager.register(_LongestFirst(), "eyestereo-longest-first")


class _LongestFirst:
    """The run's order, after every other hook (a group of pytest-split's is ordered as a whole run is)."""

    @pytest.hookimpl(trylast=True)
    def pytest_collection_modifyitems(self, config, items):
        _longest_first(config, items)


def _longest_first(config, items):
    # Longest first, so that the workers finish together: each test's recorded time (tests/durations.json, a
    # suite run's --durations), else a guess by kind (a bench a few seconds, the rest little).
    dur = _durations()

    def cost(it):
        if it.nodeid in dur:
            return dur[it.nodeid]
        return 3.0 if (it.get_closest_marker("sim") or it.get_closest_marker("othersims")) else 0.1

    items.sort(key=cost, reverse=True)
    # pytest-xdist's worksteal hands each of the N workers a contiguous 1/N of the list and lets an idle one take
    # the last half of another's queue: dealt round-robin, every worker's share runs longest first and what is
    # stolen at the end is short.
    n = _workers(config)
    if n > 1:
        items[:] = [it for k in range(n) for it in items[k::n]]


def _durations() -> dict:
    import json
    from pathlib import Path

    f = Path(__file__).resolve().parent / "durations.json"
    return json.loads(f.read_text()) if f.is_file() else {}


def _workers(config) -> int:
    """The number of xdist workers (collection runs in each worker, which learns the count from its controller)."""
    wi = getattr(config, "workerinput", None)
    if wi and "workercount" in wi:
        return int(wi["workercount"])
    n = getattr(config.option, "numprocesses", None)
    return n if isinstance(n, int) and n > 0 else 1


@pytest.fixture
def tsukuba_pair(tmp_path):
    """``make(rows, cols, shift)``: a stereo pair cut from tests/data/tsukuba_im3.png (the right view
    ``shift`` pixels further), written as ``l.png`` / ``r.png`` in the test's folder; returns their paths."""
    from pathlib import Path

    import cv2

    img = cv2.imread(str(Path(__file__).resolve().parent / "data" / "tsukuba_im3.png"), cv2.IMREAD_GRAYSCALE)

    def make(rows: slice, cols: slice, shift: int):
        cv2.imwrite(str(tmp_path / "l.png"), img[rows, cols])
        cv2.imwrite(str(tmp_path / "r.png"), img[rows, cols.start + shift:cols.stop + shift])
        return tmp_path / "l.png", tmp_path / "r.png"

    return make


@pytest.fixture
def cli(capfd):
    """``cli(*argv)``: the ``eyestereo`` command run in this process on ``argv`` (any objects, turned into
    strings); returns its exit status and what it wrote to stdout and stderr."""
    from eyestereo.tools.cli import main

    def run(*argv):
        code = main.main([str(a) for a in argv])
        out, err = capfd.readouterr()
        return code, out, err

    return run
