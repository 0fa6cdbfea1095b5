"""The WaveDrom timing diagrams render, their ASCII twins resolve, and the committed outputs are current."""

import json

import pytest

from eyestereo.hdl.flow.timing import DOC, JSON_DIR, SVG_DIR, TimingError, ascii_block, build, diagrams, load, render

pytest.importorskip("yowasp_wavedrom")


def test_every_diagram_renders_and_has_its_ascii():
    items = diagrams()
    stems = {s for s, _ in items}
    assert {"image_stream", "axis_video", "fetch_port", "coordinate_pair", "camera_bus"} <= stems
    for stem, d in items:
        svg = render(d)
        assert svg.startswith("<svg") and "</svg>" in svg[-20:], stem


def test_committed_outputs_are_make_timing_output(tmp_path):
    files = build(JSON_DIR, tmp_path / "svg", tmp_path / "timing.md")
    for f in files[:-1]:
        assert (SVG_DIR / f.name).read_text() == f.read_text(), f"{f.name}: run make timing"
    fresh = files[-1].read_text().replace("(svg/", "(img/timing/")
    assert DOC.read_text() == fresh, "docs/timing.md is not make timing's output: run make timing"
    assert "```\ncycle   0    1    2" in fresh  # the image stream's ASCII diagram, from hdl/interfaces/stream.py


def test_broken_diagrams_are_refused(tmp_path):
    good = json.loads((JSON_DIR / "image_stream.json").read_text())
    cases = {
        "short wave": lambda d: d["signal"][1].update(wave="01"),
        "data labels": lambda d: d["signal"][4]["data"].pop(),
        "no title": lambda d: d["eyestereo"].pop("title"),
        "no ascii": lambda d: d["eyestereo"].pop("ascii"),
    }
    for name, breaker in cases.items():
        d = json.loads(json.dumps(good))
        breaker(d)
        p = tmp_path / f"{name.replace(' ', '_')}.json"
        p.write_text(json.dumps(d))
        with pytest.raises(TimingError):
            load(p)
    d = json.loads(json.dumps(good))
    d["eyestereo"]["ascii"] = "eyestereo.hdl.interfaces.stream:NoSuchThing"
    one = tmp_path / "one"
    one.mkdir()
    (one / "x.json").write_text(json.dumps(d))
    with pytest.raises(TimingError, match="does not resolve"):
        build(one, one / "svg", one / "t.md")
    assert not (one / "t.md").exists() and not (one / "svg").exists()  # nothing half-written


def test_ascii_block_takes_the_cycle_diagram():
    doc = "Intro::\n\n    not this one\n\nTiming::\n\n    cycle  0  1\n    valid  _  #\n\nAfter.\n"
    assert ascii_block(doc) == "cycle  0  1\nvalid  _  #"
    with pytest.raises(TimingError):
        ascii_block("no diagram here")


def test_ascii_block_picks_the_diagram_that_contains_a_text():
    doc = ("Mono::\n\n    cycle  0  1\n    valid  _  #\n\nStereo::\n\n    cycle  0  1\n    valid  #  #\n"
           "    cam    _  #\n\nAfter.\n")
    assert ascii_block(doc) == "cycle  0  1\nvalid  _  #"
    assert ascii_block(doc, "cam") == "cycle  0  1\nvalid  #  #\ncam    _  #"
    with pytest.raises(TimingError):
        ascii_block(doc, "tready")
