"""make report: a small part of the thesis report runs, fills in what exists, and says what does not."""

import json


from eyestereo.tools.reports.thesis import SECTIONS, main

# What make synth writes (the fields the report reads), for three configurations.
FAKE_SYNTH = [
    dict(block="sobel", label="sobel", summary=dict(LUT=148, LUTRAM=0, FF=191, RAMB16=2, MULT18X18=0, carry=174),
         fmax={"clk": dict(achieved=96.5, constraint=100.0)}, clocks={"clk": 50.0}),
    dict(block="harris_mono", label="harris_mono",
         summary=dict(LUT=1337, LUTRAM=20, FF=1848, RAMB16=8, MULT18X18=7, carry=1209),
         fmax={"clk": dict(achieved=86.9, constraint=100.0)}, clocks={"clk": 50.0}),
    dict(block="convolve", label="convolve sobel-x full",
         summary=dict(LUT=171, LUTRAM=0, FF=160, RAMB16=2, MULT18X18=0, carry=90), fmax={}, clocks={"clk": 50.0}),
]


def _run(tmp_path, *extra):
    synth = tmp_path / "resources.json"
    if not synth.exists():
        synth.write_text(json.dumps(FAKE_SYNTH))
    out = tmp_path / "thesis.md"
    rc = main(["--out", str(out), "--synth", str(synth), "--framerate", str(tmp_path / "framerate.json"),
               "--quick", *extra])
    return rc, out.read_text() if out.exists() else ""


def test_resource_tables_and_missing_sections(tmp_path):
    rc, text = _run(tmp_path, "--section", "convolution", "--section", "rectifier", "--section", "stereo_harris",
                    "--section", "framerate")
    assert rc == 0
    # Table 6.3: the thesis's Sobel row (259 LUTs, 2 BRAM, 0 MUL) next to ours (148, 2, 0, 96.5 MHz -> 96).
    assert "| Sobel | 259 | 2 | 0 | 148 | 2 | 0 | 96 |" in text
    # harris_mono against the thesis's modules summed: 1812 LUTs, 8 BRAM, 8 MUL.
    assert "| 1812 | 8 | 8 | 1337 + 20 RAM | 8 | 7 | 87 |" in text
    assert "| Sobel Ix alone (`convolve`) | - | - | 171 | - |" in text  # the separable variant is missing: "-"
    assert text.count("**Not yet available:**") == 3  # rectifier, stereo Harris, measured frame rate
    assert "20.01 fps" in text and "| rectifier reads (2 x 20 Mword/s) | 20.28 |" in text


def test_measured_frame_rate_is_compared(tmp_path):
    (tmp_path / "framerate.json").write_text(json.dumps(dict(fps=25.0, frames=3, clocks={"memory": 100},
                                                             simulator="verilator")))
    rc, text = _run(tmp_path, "--section", "framerate")
    assert rc == 0 and "Measured: **25.00 fps** over 3 stereo frames" in text and "(1.25 x)" in text


def test_harris_figures_section_runs(tmp_path):
    rc, text = _run(tmp_path, "--section", "harris")
    assert rc == 0 and "![fig_5_3_5_4_harris](img/thesis/fig_5_3_5_4_harris.png)" in text
    assert (tmp_path / "img" / "thesis" / "fig_5_3_5_4_harris.png").stat().st_size > 10_000
    rows = [l for l in text.splitlines() if l.startswith("| (")]
    counts = [int(r.split("|")[2]) for r in rows]
    assert len(counts) == 3 and counts[0] > 3 * counts[1] > 0  # NMS leaves one feature per cluster


def test_a_broken_input_fails_the_run(tmp_path):
    (tmp_path / "resources.json").write_text("[{\"no\": 1}]")
    rc, text = _run(tmp_path, "--section", "convolution")
    assert rc == 1 and "**Failed:**" in text
    assert main(["--out", str(tmp_path / "x.md"), "--section", "nonsense"]) == 2
    assert not (tmp_path / "x.md").exists()


def test_every_section_is_listed_once():
    keys = [k for k, _, _ in SECTIONS]
    assert len(keys) == len(set(keys)) and {"regression", "quantized", "framerate", "stereo_harris"} <= set(keys)


def test_derived_frame_rate_is_not_called_measured(tmp_path):
    (tmp_path / "framerate.json").write_text(json.dumps(dict(
        fps=18.8, frames=6, size="48x32", clocks={"memory": 100}, simulator="ghdl",
        fps_modes={"sequential": 18.8, "overlapped": 50.7})))
    rc, text = _run(tmp_path, "--section", "framerate")
    assert rc == 0 and "Measured:" not in text
    assert "Derived for 352x288 from a measurement on 48x32 frames: **18.80 fps**" in text
    assert "overlapped 50.7 fps" in text and "(0.94 x)" in text
