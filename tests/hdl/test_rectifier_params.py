"""Elaboration checks of poly_unit and coordinate_warper: bad ports and parameters give one ValueError that
names them; the interfaces and the catalogue entries are sized from the calibration."""

import pytest
from myhdl import ResetSignal, Signal, intbv

from eyestereo.hdl.flow.catalog import BLOCKS
from eyestereo.hdl.interfaces.coord_pair import CoordPair
from eyestereo.hdl.rectify.calibration import calibration_param
from eyestereo.hdl.rectify.coordinate_warper import coordinate_warper
from eyestereo.hdl.rectify.poly_unit import CoefPort, poly_unit
from eyestereo.tools.models import poly_unit as unit

SPEC = "seed:3:2@40x20"


@pytest.fixture(scope="module")
def cal():
    return calibration_param(SPEC)


def unit_ports(cal, frac=5, **over):
    p = dict(clk=Signal(bool(0)), rst=ResetSignal(0, active=1, isasync=False), enable=Signal(bool(0)),
             x=Signal(intbv(0)[unit.int_bits(cal.width):]), y=Signal(intbv(0)[unit.int_bits(cal.height):]),
             select_coord=Signal(intbv(0)[3:]), coord=Signal(intbv(0)[unit.coord_bits(cal, frac):]),
             out_of_range=Signal(bool(0)), select_coord_out=Signal(intbv(0)[3:]), coef=None)
    p.update(over)
    return p


def build_unit(cal, frac=5, params=None, **over):
    p = unit_ports(cal, frac, **over)
    return poly_unit(*p.values(), quantizers=cal, frac=frac, **(params or {}))


def test_poly_unit_elaborates(cal):
    assert build_unit(cal, coef=CoefPort(unit.coef_data_bits(cal.formats))) is not None


@pytest.mark.parametrize("over,match", [
    (dict(rst=Signal(bool(0))), "port rst"),
    (dict(x=Signal(intbv(0)[9:])), "port x must be 6 bits wide"),
    (dict(y=Signal(intbv(0, min=-16, max=16))), "port y must be unsigned"),
    (dict(select_coord=Signal(intbv(0)[2:])), "port select_coord must be 3 bits wide"),
    (dict(coord=Signal(intbv(0)[20:])), "port coord must be 14 bits wide"),
    (dict(enable=Signal(intbv(0)[2:])), "port enable must be 1 bit wide"),
    (dict(coef=CoefPort(3)), "port coef must carry"),
    (dict(coef=Signal(bool(0))), "port coef must be a CoefPort"),
    (dict(out_of_range="shared"), "ports out_of_range and enable share a signal"),
])
def test_poly_unit_rejects_ports(cal, over, match):
    if over.get("out_of_range") == "shared":
        enable = Signal(bool(0))
        over = dict(enable=enable, out_of_range=enable)
    with pytest.raises(ValueError, match=match):
        build_unit(cal, **over)


@pytest.mark.parametrize("params,match", [
    (dict(frac=-1), "frac"), (dict(frac=2.0), "frac"), (dict(frac=17), "frac"),
    (dict(quantizers="nope"), "poly_unit: parameter quantizers: unknown calibration spec"),
    (dict(quantizers=42), "parameter quantizers must be"),
    (dict(quantizers="/no/such/quantizers.json"), "parameter quantizers: .*does not exist"),
    (dict(source_width=1), "source_width"),
    (dict(source_height=2.5), "source_height"),
])
def test_poly_unit_rejects_parameters(cal, params, match):
    p = unit_ports(cal)
    kw = dict(quantizers=cal, frac=5)
    kw.update(params)
    with pytest.raises(ValueError, match=match):
        poly_unit(*p.values(), **kw)


def warper_ports(cal, frac=5, **over):
    p = dict(clk=Signal(bool(0)), rst=ResetSignal(0, active=1, isasync=False), start=Signal(bool(0)),
             enable=Signal(bool(0)), busy=Signal(bool(0)), done=Signal(bool(0)),
             coord=CoordPair(cal.source_width, cal.source_height, frac))
    p.update(over)
    return p


def test_warper_elaborates_and_checks(cal):
    assert coordinate_warper(*warper_ports(cal).values(), quantizers=cal, frac=5) is not None
    with pytest.raises(ValueError, match="port coord is sized for 352x288 images and frac 4"):
        coordinate_warper(*warper_ports(cal, coord=CoordPair(352, 288, 4)).values(), quantizers=cal, frac=5)
    with pytest.raises(ValueError, match="port coord must be a CoordPair"):
        coordinate_warper(*warper_ports(cal, coord=Signal(bool(0))).values(), quantizers=cal, frac=5)
    with pytest.raises(ValueError, match="coordinate_warper: port start must be 1 bit wide"):
        coordinate_warper(*warper_ports(cal, start=Signal(intbv(0)[2:])).values(), quantizers=cal, frac=5)


def test_interfaces_are_sized_from_the_camera():
    c = CoordPair(352, 288, 5)
    assert (len(c.xl), len(c.yl), len(c.xr), len(c.yr)) == (14, 14, 14, 14)  # ufix[14,5], the thesis's
    c = CoordPair(640, 480, 6)
    assert (len(c.xl), len(c.yl)) == (16, 15)
    assert c.fields() == ["valid", "read_ack", "xl", "yl", "xr", "yr", "oor_l", "oor_r", "eol", "eof"]
    for bad in (dict(source_width=1), dict(frac=-1), dict(source_height=2.0)):
        with pytest.raises(ValueError):
            CoordPair(**{**dict(source_width=352, source_height=288, frac=5), **bad})
    with pytest.raises(ValueError, match="data_bits"):
        CoefPort(0)


def test_catalogue_entries(cal):
    # (the default configurations are elaborated by test_params.py)
    for name in ("poly_unit", "coordinate_warper"):
        spec = BLOCKS[name]
        assert spec.build is not None and spec.params()["quantizers"] == "rig"
        ports, kw, _ = spec.ports(quantizers=SPEC)
        assert "coef" not in ports and list(ports)[:2] == ["clk", "rst"] and kw["quantizers"] == SPEC
        ports, _, _ = spec.ports(quantizers=SPEC, coefficients="register", frac=3)
        assert ports["coef"].data_bits == unit.coef_data_bits(cal.formats)
        with pytest.raises(ValueError, match="coefficients must be"):
            spec.elaborate(quantizers=SPEC, coefficients="rom")
    _, ports, _ = BLOCKS["coordinate_warper"].elaborate(quantizers=SPEC, coefficients="register")
    assert ports["coord"].frac == unit.resolve_frac(cal) and ports["coord"].source_width == 352
    assert len(ports["coord"].xl) == unit.int_bits(352) + unit.resolve_frac(cal)
    assert list(ports) == ["clk", "rst", "start", "enable", "busy", "done", "coord", "coef"]
