"""The port bundles are declared once (hdl/interfaces/bundle.py): the signals, the field order, the checks,
check_distinct's directions and docs/interfaces.md all come from each class's MEMBERS."""

import pytest
from myhdl import Signal, intbv

from eyestereo.hdl.common.checks import check_distinct, check_port
from eyestereo.hdl.flow import ports as port_doc
from eyestereo.hdl.interfaces.axil import AxiLite, check_axil
from eyestereo.hdl.interfaces.axis import AxiStream
from eyestereo.hdl.interfaces.bundle import IN, OUT, Bundle, Member
from eyestereo.hdl.interfaces.camera_bus import CameraBus
from eyestereo.hdl.interfaces.coord_pair import CoordPair
from eyestereo.hdl.interfaces.fetch_port import FetchPort, check_fetch
from eyestereo.hdl.interfaces.queue import QueuePort, check_queue
from eyestereo.hdl.interfaces.sram_bus import HostPort, SramCmd, SramPins, SramRsp, StatPort, check_bundle
from eyestereo.hdl.interfaces.stream import ImageStream

BUNDLES = [ImageStream(8), ImageStream(8, stereo=True), QueuePort(16), FetchPort(40, 30), CoordPair(40, 30, 5),
           SramPins(), SramCmd(tag_bits=3), SramRsp(tag_bits=3), HostPort(), StatPort(5, 16), CameraBus(),
           AxiLite(12), AxiStream(12)]


@pytest.mark.parametrize("bundle", BUNDLES, ids=repr)
def test_members_make_the_signals_in_port_order(bundle):
    assert isinstance(bundle, Bundle)
    assert bundle.fields() == [m.name for m in bundle.members()]
    for m in bundle.members():
        sig = getattr(bundle, m.name)
        assert isinstance(sig, type(Signal(bool(0))))
        assert (len(sig) if m.width is not bool else 1) == m.bits(bundle)
    check_port("p", bundle, type(bundle))  # a fresh bundle passes its own check
    assert set(bundle.driven(True)) | set(bundle.driven(False)) == set(bundle.fields())


def test_widths_and_initial_values_as_before():
    # written out here, not taken from the declarations: the bundles' signals before issue 22
    pins = SramPins()
    enables = (bool(pins.ce_n.val), bool(pins.we_n.val), bool(pins.oe_n.val), bool(pins.ld_n.val))
    assert enables == (True, True, True, False)
    assert int(pins.bw_n.val) == 3 and len(pins.bw_n) == 2 and len(pins.addr) == 20 and len(pins.dq_i) == 16
    f = FetchPort(352, 288)
    assert (f.req_x.min, f.req_x.max, len(f.req_x), f.req_y.max) == (0, 352, 9, 288)
    assert len(AxiStream(12).tdata) == 16 and len(AxiLite(12).awaddr) == 12 and len(AxiLite(12).rdata) == 32
    c = CoordPair(352, 288, 5)
    assert [len(getattr(c, n)) for n in ("xl", "yl", "xr", "yr")] == [14, 14, 14, 14]
    assert SramCmd(tag_bits=3).fields() == ["valid", "ready", "we", "addr", "wdata", "be", "tag"]
    assert QueuePort(16).fields() == ["data", "valid", "ready", "eol", "eof"]


def test_directions():
    assert QueuePort(8).driven(producer=False) == ["ready"]
    assert FetchPort().driven(producer=False) == ["req_ready", "rsp_valid", "rsp_idx", "rsp_data"]
    assert AxiLite().driven(producer=False) == ["awready", "wready", "bresp", "bvalid", "arready", "rdata", "rresp",
                                               "rvalid"]
    assert SramPins().driven(producer=False) == ["dq_i"]
    assert ImageStream(8, stereo=True).driven(producer=False) == []
    with pytest.raises(ValueError, match="flow must be"):
        Member("x", bool, "inout")
    assert (IN, OUT) == ("in", "out")


def test_check_port_messages_name_the_members():
    with pytest.raises(ValueError,
                       match=r"port q must be a QueuePort, got None \(QueuePort members: data, valid, ready"):
        check_queue("q", None)
    with pytest.raises(ValueError, match=r"port f must be a FetchPort, got ImageStream.*req_valid, req_ready"):
        check_fetch("f", ImageStream(8))
    with pytest.raises(ValueError, match=r"port bus must be an AxiLite, got int 3"):
        check_axil("bus", 3)
    with pytest.raises(ValueError, match=r"port s must be an ImageStream.*cam \(if stereo\)"):
        check_port("s", QueuePort(8), ImageStream)
    h = HostPort()
    h.req_we = Signal(intbv(0)[2:])
    with pytest.raises(ValueError, match=r"port host: field req_we must be a Signal\(bool\)"):
        check_bundle("host", h, HostPort)
    q = QueuePort(8)
    q.data = Signal(intbv(0)[9:])
    with pytest.raises(ValueError,
                       match=r"port q: its data field is a 9-bit unsigned Signal\(intbv\), the QueuePort says 8"):
        check_queue("q", q)


def test_check_distinct_takes_directions_from_the_declaration():
    q, f = QueuePort(8), FetchPort()
    check_distinct(dict(fetch=f), dict(q=q))                 # distinct bundles
    rdy = Signal(bool(0))
    check_distinct(dict(source=ImageStream(8)), dict(a=rdy, b=rdy))  # read-only signals may be shared
    # a consumer drives the queue's ready: sharing it with another input is refused
    q.ready = rdy
    with pytest.raises(ValueError, match=r"ports q and stall share a signal; the output port q"):
        check_distinct({}, dict(q=q, stall=rdy))
    # a producer only reads ready: the same sharing is fine there
    check_distinct(dict(q=q), dict(stall=rdy))
    # the fetch port's master drives req_x; the slave drives the responses
    x = f.req_x
    with pytest.raises(ValueError, match=r"ports fetch and x share a signal; the output port fetch"):
        check_distinct(dict(fetch=f), dict(x=x))
    check_distinct({}, dict(fetch=f, x=x))
    with pytest.raises(ValueError, match=r"ports fetch and d share a signal; the output port fetch"):
        check_distinct({}, dict(fetch=f, d=f.rsp_data))


def test_docs_interfaces_page_is_current():
    assert port_doc.main(["--check"]) == 0, "docs/interfaces.md is stale: python -m eyestereo.hdl.flow.ports"
    text = port_doc.page()
    assert "| `ready` | in | out | 1 | 1 |" in text       # QueuePort: the consumer drives ready
    assert "| `req_x` | out | in | `0..width-1` | 9 |" in text
    assert "| `cam` (if `stereo`) | out | in | 1 | 1 |" in text
