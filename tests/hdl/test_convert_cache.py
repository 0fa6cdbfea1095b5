"""The benches' conversion cache (sim/lib/runner.py: cached_convert): a configuration converted once is copied,
not converted again, while the sources are the same; objects and files as parameters are never cached."""

from eyestereo.sim.lib import runner


def test_a_configuration_is_converted_once_then_copied(tmp_path, monkeypatch):
    monkeypatch.setattr(runner, "CONVERT_CACHE", tmp_path / "cache")
    calls = []
    real = runner.convert

    def counting(block, path, **kw):
        calls.append((block, kw))
        return real(block, path, **kw)

    monkeypatch.setattr(runner, "convert", counting)
    a, b, c = (tmp_path / n for n in "abc")
    for d in (a, b, c):
        d.mkdir()
    first = runner.cached_convert("line_delay", a, width=8)
    second = runner.cached_convert("line_delay", b, width=8)
    assert len(calls) == 1
    assert [f.name for f in first] == [f.name for f in second]
    assert all(f.read_text() == g.read_text() for f, g in zip(first, second))
    runner.cached_convert("line_delay", c, width=9)  # another configuration: converted
    assert len(calls) == 2


def test_objects_and_files_are_never_keys():
    assert runner._plain(dict(width=8, quantizers="rig:64x48", blocks=(4, 4)))
    assert not runner._plain(dict(quantizers="build/cache/quantizers.json"))
    assert not runner._plain(dict(quantizers="opencv@352x288"))
    assert not runner._plain(dict(coef=object()))


def test_the_key_follows_the_sources(tmp_path, monkeypatch):
    monkeypatch.setattr(runner, "CONVERT_CACHE", tmp_path / "cache")
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    runner.cached_convert("line_delay", tmp_path / "a", width=8)
    monkeypatch.setattr(runner, "_source_key", lambda: "changed sources")
    runner.cached_convert("line_delay", tmp_path / "b", width=8)
    assert len(list((tmp_path / "cache").iterdir())) == 2
