"""MyHDL's instance names do not grow from one conversion to the next in one process (issue 26: in a test worker
that had converted the front end many times, nested blocks' names passed GHDL's 1023-character limit)."""

from eyestereo.hdl.flow.convert import convert


def longest_identifier(text: str) -> int:
    return max(len(w) for w in text.replace("(", " ").replace(")", " ").split())


def test_the_names_of_a_conversion_do_not_depend_on_the_ones_before(tmp_path):
    texts = ["\n".join(x for x in convert("sobel", tmp_path / str(i), stereo=True)[-1].read_text().splitlines()
                       if not x.startswith("--"))  # the header comments name the file and the time
             for i in range(3)]
    assert texts[0] == texts[1] == texts[2]
    assert longest_identifier(texts[0]) < 200
