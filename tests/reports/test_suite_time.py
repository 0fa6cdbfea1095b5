"""docs/suite.md's writer: what it reads from pytest's output, and its refusals (the suite itself is not run)."""

from eyestereo.sim.measure import suite_time


def test_document_lists_the_figures_and_the_slowest_tests():
    res = dict(wall=549.4, cpu=1047.0, summary="2267 passed", cmd="-m pytest -n 2", rc=0,
               slow=[("45.42", "call", "tests/hdl/test_stereo_frontend.py::test_stereo_frontend[overlapped]")])
    text = suite_time.document(res, 2)
    assert "| wall time | 9 min 09 s |" in text
    assert "| CPU time (all processes: workers and simulators) | 17 min 27 s |" in text
    assert "| tests | 2267 passed |" in text
    assert "| 45.42 | call | `tests/hdl/test_stereo_frontend.py::test_stereo_frontend[overlapped]` |" in text


def test_bad_jobs_writes_nothing(tmp_path, capsys):
    out = tmp_path / "suite.md"
    assert suite_time.main(["--jobs", "0", "--out", str(out)]) == 2
    assert not out.exists()
    assert capsys.readouterr().err.strip() == "suite_time: --jobs must be at least 1"


def test_a_failed_suite_writes_nothing(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(suite_time, "run", lambda jobs: dict(rc=1, tail=["1 failed, 3 passed"]))
    out = tmp_path / "suite.md"
    assert suite_time.main(["--out", str(out)]) == 1
    assert not out.exists() and "the suite failed (exit 1); nothing written" in capsys.readouterr().err
