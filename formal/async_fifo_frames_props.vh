// Frame-level properties of async_fifo: the queue read port's frame rule, the dropped-frame counter and
// the rrst skip (formal/run.py includes this file into MyHDL's Verilog of the block, just before
// endmodule). Run with depth=4 (3-bit pointers), data_width=2 (4-bit memory words {eof, eol, data}).
// Model: multiclock on, both clocks free (any ratio, phase, simultaneous edges), inputs synchronous to
// their clock, both resets free at any time, source_ready free. No protocol is assumed of the sink: a
// "frame" is what the FIFO sees, the pixels since the last frame end (an eof pixel, a reset token, wrst).
//
// Ghost state: the writer tags every word it writes with (frame number, word index in that frame) and
// keeps a copy of the word taken in; the tags travel through a ghost memory beside `mem` and a ghost
// output register beside `q`. Frame numbers count the frames that got a word into the memory; word
// indices count the frame's pixels taken in by the sink (written or lost), modulo 8.
//
// Defines (from the job's header or the launcher): F_PORT_ONLY keeps only the properties at the port
// (the frame rule, rrst, `dropped`), without the write side's properties and the invariants: a bounded
// check whose mutants show that a consumer of the port sees each bug. F_REGULAR_CLOCKS constrains both
// clocks to rise together every second step (the cover task, and that bounded check): its traces are
// traces of the free model, found in seconds where the free clocks take minutes beyond ~16 steps.

reg f_past = 1'b0;
always @($global_clock) f_past <= 1'b1;

// ---- inputs synchronous to their clock (as async_fifo_props.vh) ---------------------------------------
reg f_wclk_p = 1'b0, f_rclk_p = 1'b0;
reg [3:0] f_win_p = 4'd0;
reg [1:0] f_sdata_p = 2'd0;
reg [1:0] f_rin_p = 2'd0;
always @($global_clock) begin
    f_wclk_p <= wclk;
    f_rclk_p <= rclk;
    f_win_p <= {wrst, sink_valid, sink_eol, sink_eof};
    f_sdata_p <= sink_data;
    f_rin_p <= {rrst, source_ready};
end
wire f_wrose = f_past && wclk && !f_wclk_p;
wire f_rrose = f_past && rclk && !f_rclk_p;
always @($global_clock) if (f_past) begin
    if (!f_wrose) assume({wrst, sink_valid, sink_eol, sink_eof} == f_win_p && sink_data == f_sdata_p);
    if (!f_rrose) assume({rrst, source_ready} == f_rin_p);
end

// ---- tags ----------------------------------------------------------------------------------------------
// A word is a token when eof is high and eol low (a sink pixel never is); a word "closes" its frame when
// its eof bit is high (the frame's eof pixel, or a token). follows(a, b): word b may come right after a in
// a well-formed stream: after a closing word the first pixel (index 0) of the next frame, else the next
// word (pixel or token) of the same frame.
function f_follows(input [2:0] af, input [2:0] ai, input ac, input [2:0] bf, input [2:0] bi, input [3:0] bw);
    f_follows = ac ? (bw[3:2] != 2'b10 && bi == 3'd0 && bf == af + 3'd1) : (bf == af && bi == ai + 3'd1);
endfunction

// ---- the write side's ghost ----------------------------------------------------------------------------
wire f_pix = sink_valid && (sink_eol || !sink_eof);   // the sink's beats, decoded here (not the block's)
wire f_tok = sink_valid && sink_eof && !sink_eol;
wire f_wpix = we && !wr_tok;                           // a pixel written
wire f_lost = !wrst && f_pix && !f_wpix;               // a pixel taken in but not written
reg [2:0] f_wi = 3'd0;     // pixels of the current frame taken in (the next pixel's index), mod 8
reg f_win = 1'b0;          // a frame is under way (a pixel taken in since the last frame end)
reg f_wgap = 1'b0;         // ... and lost a pixel
reg f_wcur = 1'b0;         // ... and wrote a word (the memory's last frame is the current one)
reg [2:0] f_wtf = 3'd0, f_wti = 3'd0;  // tag of the last word written (the memory stream's tail) ...
reg f_wtc = 1'b1;                      // ... and whether it closes its frame (at start: a closed frame 0)
reg [15:0] f_cnt = 16'd0;  // frames with pixels that ended without being written whole
reg f_ov = 1'b0;           // for the covers: a frame with words in the memory lost a pixel (an overflow) ...
reg [2:0] f_ovf = 3'd0;    // ... its frame number
reg [2:0] f_gf [0:3];      // the ghost memory: tags and the word taken in
reg [2:0] f_gi [0:3];
reg [3:0] f_gw [0:3];
// the tag of the word written now
wire [2:0] f_nf = wr_tok ? f_wtf : (f_wcur ? f_wtf : f_wtf + 3'd1);
wire [2:0] f_ni = wr_tok ? f_wti + 3'd1 : f_wi;
wire [3:0] f_nw = wr_tok ? 4'b1000 : {sink_eof, sink_eol, sink_data};
wire f_wend = wrst || f_tok || (f_pix && sink_eof);   // the current frame ends at this write edge
wire f_drop = wrst ? f_win : f_tok ? f_win : (f_pix && sink_eof && (f_wgap || f_lost));
always @(posedge wclk) begin
    if (we) begin
        f_gf[waddr] <= f_nf;
        f_gi[waddr] <= f_ni;
        f_gw[waddr] <= f_nw;
        f_wtf <= f_nf;
        f_wti <= f_ni;
        f_wtc <= f_nw[3];
    end
    if (f_drop) f_cnt <= f_cnt + 16'd1;
    if (f_lost && f_wcur && !f_wgap) begin
        f_ov <= 1'b1;
        f_ovf <= f_wtf;
    end
    if (f_wend) begin
        f_wi <= 3'd0;
        f_win <= 1'b0;
        f_wgap <= 1'b0;
        f_wcur <= 1'b0;
    end else if (f_pix) begin
        f_wi <= f_wi + 3'd1;
        f_win <= 1'b1;
        f_wgap <= f_wgap || f_lost;
        f_wcur <= f_wcur || f_wpix;
    end
end

// ---- the read side's ghost -----------------------------------------------------------------------------
reg [2:0] f_qf = 3'd0, f_qi = 3'd0;   // the output register's tag and word taken in
reg [3:0] f_qw = 4'd0;
reg [2:0] f_lf = 3'd0, f_li = 3'd0;   // the last word that left the output register (taken, dropped by
reg f_lc = 1'b1;                      // the skip or discarded by rrst): tag, closes
// The port model (the consumer's view, from the words it took): inside a frame, the frame's number and
// the index of the next word. rrst resets it (the consumer is reset with the port).
reg f_pin = 1'b0;
reg [2:0] f_pf = 3'd0, f_pi = 3'd0;
reg f_rmid = 1'b0, f_skipped = 1'b0;  // for the covers: rrst inside a frame; a word then skipped
wire f_left = take || drop_q || (rrst && q_full);
always @(posedge rclk) begin
    if (load) begin
        f_qf <= f_gf[raddr];
        f_qi <= f_gi[raddr];
        f_qw <= f_gw[raddr];
    end
    if (f_left) begin
        f_lf <= f_qf;
        f_li <= f_qi;
        f_lc <= f_qw[3];
    end
    if (rrst) begin
        f_pin <= 1'b0;
        if (f_pin) f_rmid <= 1'b1;
    end else if (take) begin
        f_pin <= !f_qw[3];
        f_pf <= f_qf;
        f_pi <= f_qi + 3'd1;
    end
    if (f_rmid && drop_q) f_skipped <= 1'b1;
end

// ---- the memory stream, in order: last word out, q, mem[rbin], ..., mem[wbin - 1] = tail ---------------
wire [2:0] f_occ = wbin - rbin;
wire [1:0] f_a0 = rbin[1:0], f_a1 = rbin[1:0] + 2'd1, f_a2 = rbin[1:0] + 2'd2, f_a3 = rbin[1:0] + 2'd3;
wire [1:0] f_at = wbin[1:0] - 2'd1;
// the word before the memory's first: q if it holds one, else the last word out
wire [2:0] f_hf = q_full ? f_qf : f_lf, f_hi = q_full ? f_qi : f_li;
wire f_hc = q_full ? f_qw[3] : f_lc;

// the ghost count of dropped frames: the frames ended without being written whole, and the frame under
// way if it has lost a pixel (counted from its first lost pixel on)
wire [15:0] f_gcnt = f_cnt + {15'd0, f_wgap};

// ---- the properties at the port (F_PORT_ONLY: these alone, as a bounded check, for the mutants) ------------
always @(*) begin
    // (1) the port: every word offered is the word the sink gave (or a token), and the frames come whole
    // or cut by a token after a prefix: outside a frame only a frame's first pixel; inside, the frame's
    // next word (its next pixel, or a token right after the prefix taken). With the writer's side below
    // (each frame's written words are a prefix of its pixels, an eof pixel only when the frame was written
    // whole), a frame that ends with eof at the port is every pixel the sink gave for it, in order.
    if (source_valid) begin
        assert({source_eof, source_eol, source_data} == f_qw);
        if (f_pin) assert(f_qf == f_pf && f_qi == f_pi);
        else assert(f_qw[3:2] != 2'b10 && f_qi == 3'd0);
    end
    // (3) rrst: the port is idle during it and presents nothing until the skip ends (above: after rrst the
    // port model is outside a frame, so the next word presented is a frame's first pixel)
    if (rrst) assert(!source_valid);
end

// (2) the counter at the port: `dropped` is the ghost count as it was three read edges before (so a value
// the count had, never ahead of it), and equals the count from the third read edge after its last change
// on (a read edge in the same step as the write edge samples the old count: not counted)
reg [15:0] f_c1 = 16'd0, f_c2 = 16'd0, f_c3 = 16'd0;
reg f_rck = 1'b0;  // a read edge has come: `dropped` (an output register) has no initial value before it
always @(posedge rclk) begin
    f_rck <= 1'b1;
    f_c1 <= f_gcnt;
    f_c2 <= f_c1;
    f_c3 <= f_c2;
end
reg [15:0] f_gcnt_p = 16'd0, f_cgray_p = 16'd0;
reg [1:0] f_rs_p = 2'd3;  // read edges since the count last changed, saturating at 3
wire [1:0] f_rs = (f_past && f_gcnt != f_gcnt_p) ? 2'd0 : (f_rrose && f_rs_p != 2'd3) ? f_rs_p + 2'd1 : f_rs_p;
always @($global_clock) begin
    f_gcnt_p <= f_gcnt;
    f_cgray_p <= cgray;
    f_rs_p <= f_rs;
end
always @(*) begin
    if (f_rck) assert(dropped == f_c3);
    if (f_rck && f_rs == 2'd3) assert(dropped == f_gcnt);
end

`ifndef F_PORT_ONLY
// ---- the write side's properties ---------------------------------------------------------------------------
always @(*) begin
    // (1) a word is written only as a pixel of the sink or a token; a pixel only if no pixel of its frame
    // was lost before it; every word follows the tail (a frame's words are consecutive, a token only
    // closes a frame with words in the memory, a new frame only after the last is closed)
    if (f_wpix) assert(f_pix && !f_wgap);
    if (we) assert(f_follows(f_wtf, f_wti, f_wtc, f_nf, f_ni, f_nw));
    // the memory stream's last frame stays open only while it is still being written whole (the frame
    // under way, no pixel lost); otherwise (a pixel lost, cut by a token or wrst, ...) it owes a token,
    // pending; a pending token goes at the next write edge with space
    if (!f_wtc) assert((f_wcur && !f_wgap) || tok_pend);
    if (tok_pend && !full_s && !wrst) assert(wr_tok);
    // the next frame that finds space (not full, no token pending) from its first pixel on is written whole
    if (f_pix && !wrst && !f_wgap && !full_s && !tok_pend) assert(f_wpix);
    // (2) the dropped-frame counter is the ghost count: one per frame with pixels not written whole
    // (counted at its first lost pixel, or when cut by a token or wrst); none for a whole frame or for a
    // token between frames; the Gray code that crosses is the count's, the synchronisers carry its samples
    assert(cbin == f_gcnt);
    assert(cgray == (cbin ^ (cbin >> 1)));
    assert(cgray_s1 == (f_c1 ^ (f_c1 >> 1)) && cgray_s2 == (f_c2 ^ (f_c2 >> 1)));
end
always @($global_clock) if (f_past) begin
    // the count steps by one at most, its Gray code by one bit (what makes a sample mid-change safe)
    assert(cbin == f_gcnt_p || cbin == f_gcnt_p + 16'd1);
    assert($onehot0(cgray ^ f_cgray_p));
end

// ---- invariants (they close the induction) ----------------------------------------------------------------
// the pointer invariants of async_fifo_props.vh (proven there; repeated here, they close this induction
// too): Gray = Gray(binary), the synchronised pointers lag in pointer order, occupancy at most the depth
function [2:0] f_g2b(input [2:0] g);
    f_g2b = {g[2], g[2] ^ g[1], g[2] ^ g[1] ^ g[0]};
endfunction
wire [2:0] f_rs1 = f_g2b(rgray_s1), f_rs2 = f_g2b(rgray_s2), f_ws1 = f_g2b(wgray_s1), f_ws2 = f_g2b(wgray_s2);
// each difference modulo 8 (3-bit wires), their sums without wrapping (5 bits)
wire [2:0] f_d1 = f_rs1 - f_rs2, f_d2 = rbin - f_rs1, f_d3 = f_ws2 - rbin, f_d4 = f_ws1 - f_ws2;
wire [2:0] f_d5 = wbin - f_ws1, f_d6 = wbin - f_rs2;
wire [4:0] f_wchain = f_d1 + f_d2 + f_occ;
wire [4:0] f_rchain = f_d3 + f_d4 + f_d5;
always @(*) begin
    assert(wgray == (wbin ^ (wbin >> 1)) && rgray == (rbin ^ (rbin >> 1)));
    assert(f_wchain == f_d6 && f_d6 <= 3'd4);
    assert(f_rchain == f_occ);
    assert(full_s == (wbin - f_rs2 == 3'd4) && empty_s == (rbin == f_ws2));
    // the write side's state is the ghost's
    assert(started == f_win && bad == f_wgap);
    assert(f_win == (f_wgap || f_wcur));
    if (!f_win) assert(f_wi == 3'd0);
    if (mid) assert(!tok_pend);
    assert(mid == (f_wcur && !f_wgap));
    assert(f_wtc == !(mid || tok_pend));
    if (mid) assert(f_wti + 3'd1 == f_wi && f_gw[f_at][3:2] != 2'b10);
    if (tok_pend) assert(f_wgap || !f_wcur);
    // the stream in memory is well formed and continues from the word before it
    if (q_full) assert(f_follows(f_lf, f_li, f_lc, f_qf, f_qi, f_qw));
    if (f_occ >= 3'd1) assert(f_follows(f_hf, f_hi, f_hc, f_gf[f_a0], f_gi[f_a0], f_gw[f_a0]));
    if (f_occ >= 3'd2) assert(f_follows(f_gf[f_a0], f_gi[f_a0], f_gw[f_a0][3], f_gf[f_a1], f_gi[f_a1], f_gw[f_a1]));
    if (f_occ >= 3'd3) assert(f_follows(f_gf[f_a1], f_gi[f_a1], f_gw[f_a1][3], f_gf[f_a2], f_gi[f_a2], f_gw[f_a2]));
    if (f_occ >= 3'd4) assert(f_follows(f_gf[f_a2], f_gi[f_a2], f_gw[f_a2][3], f_gf[f_a3], f_gi[f_a3], f_gw[f_a3]));
    if (f_occ == 3'd0) assert(f_wtf == f_hf && f_wti == f_hi && f_wtc == f_hc);
    else assert(f_wtf == f_gf[f_at] && f_wti == f_gi[f_at] && f_wtc == f_gw[f_at][3]);
    // the memory holds the words taken in, q the one loaded
    if (f_occ >= 3'd1) assert(mem[f_a0] == f_gw[f_a0]);
    if (f_occ >= 3'd2) assert(mem[f_a1] == f_gw[f_a1]);
    if (f_occ >= 3'd3) assert(mem[f_a2] == f_gw[f_a2]);
    if (f_occ >= 3'd4) assert(mem[f_a3] == f_gw[f_a3]);
    if (q_full) assert(q == f_qw);
    assert(q_eof == q[3] && last_eof == f_lc);
    // the read side: the port model is the stream position, except while skipping after rrst
    if (skip) assert(!f_pin && !f_lc);
    else begin
        assert(f_pin == !f_lc);
        if (f_pin) assert(f_pf == f_lf && f_pi == f_li + 3'd1);
    end
    // the counter's samples: equal to the count from the 1st, 2nd, 3rd read edge after its change on
    if (f_rs >= 2'd1) assert(f_c1 == f_gcnt);
    if (f_rs >= 2'd2) assert(f_c2 == f_gcnt);
    if (f_rs == 2'd3) assert(f_c3 == f_gcnt);
end
`endif

// ---- covers ----------------------------------------------------------------------------------------------
`ifdef F_REGULAR_CLOCKS
// Both clocks toggle at every step, rising together every second step (see the defines above).
always @($global_clock) begin
    assume(wclk == !f_wclk_p && rclk == !f_rclk_p);
end
`endif
always @(*) begin
    // an overflow cuts a frame with words in the memory, and its token arrives at the port
    cover(f_ov && source_valid && f_qw[3:2] == 2'b10 && f_qf == f_ovf && f_qi != 3'd0);
    // a whole frame (2 pixels or more) delivered right after a frame cut by an overflow
    cover(f_ov && source_valid && f_qw[3] && f_qw[2] && f_qf == f_ovf + 3'd1 && f_qi != 3'd0);
    // rrst inside a frame: the rest skipped, then a frame's first pixel presented
    cover(f_skipped && source_valid);
    // a frame's first pixel lost although the FIFO is not full: a token still pending takes the write
    // (one write per clock); the frame is dropped and counted
    cover(f_pix && !wrst && !f_win && !full_s && tok_pend);
    // dropped not yet caught up two read edges after a change (the bound 3 is tight)
    cover(f_rs == 2'd2 && dropped != f_gcnt);
end
