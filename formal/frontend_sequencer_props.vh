// Formal properties of frontend_sequencer (formal/run.py includes this file into MyHDL's Verilog of the block,
// just before endmodule). The block has no parameters. One clock.
// The environment is assumed fair, with bounds (clocks):
//   * the arbiter (ctl_cam_held): a pair is taken only while cam_want was high, held until cam_release, let go
//     one or two clocks after it; while cam_want is high and no pair held, a pair is taken within F_H clocks;
//   * the rectifier (rect_busy): rises only the clock after rect_start, is high in the 2 clocks after it
//     (rectifier.py: "busy from the clock after start"), stays high at most F_R clocks in a row;
//   * the feature lists (list_done): one pulse per rectified frame (a fall of rect_busy), at least a clock
//     after that fall and within F_L clocks of it; a frame's lists are complete before the next frame's
//     rectification ends (the Harris pipeline's latency is lines, a rectification a whole frame);
//   * mode, continuous, start, stop, list_overflow free; rst in the first clock.
// Asserted (no deadlock in either mode, as bounded response; every started frame completes):
//   * while busy, the next rect_start or the end of busy (busy low) comes within F_N clocks;
//   * once the session is not to continue (single-shot, or stop), busy falls within F_M clocks, after at
//     most one more rect_start;
//   * busy falls only when every rectified frame's lists are complete (frames counts them all);
//   * rect_start only while a pair is held, one taken since the last release (never the released pair
//     again); cam_release only while held and the rectifier is idle;
//   * the overlapped mode's count of frames whose lists are pending is exact; frames counts list_done.
localparam F_H = 3, F_R = 3, F_L = 8;
localparam F_N = 16, F_M = 17;

reg f_past = 1'b0;
always @(posedge clk) f_past <= 1'b1;
always @(*) if (!f_past) assume(rst);

// ---- the environment (assumed) ---------------------------------------------------------------------------
reg f_held_p = 1'b0, f_want_p = 1'b0, f_rel_p = 1'b0, f_rel_pp = 1'b0, f_busy_p = 1'b0, f_rs_p = 1'b0, f_rs_pp = 1'b0;
always @(posedge clk) begin
    f_held_p <= ctl_cam_held;
    f_want_p <= ctl_cam_want && !rst;
    f_rel_p <= ctl_cam_release && !rst;  // the outputs are undefined before the first reset
    f_rel_pp <= f_rel_p;
    f_busy_p <= rect_busy;
    f_rs_p <= rect_start && !rst;
    f_rs_pp <= f_rs_p;
end
reg [2:0] f_hwait = 3'd0, f_rlen = 3'd0, f_lage = 3'd0;
reg f_lpend = 1'b0;                      // a rectified frame's lists are not complete
wire f_fall = f_busy_p && !rect_busy;    // the rectification of a frame has ended (first clock low)
always @(posedge clk) begin
    f_hwait <= (ctl_cam_want && !ctl_cam_held && f_hwait != 3'd7) ? f_hwait + 3'd1 : 3'd0;
    f_rlen <= (rect_busy && f_rlen != 3'd7) ? f_rlen + 3'd1 : 3'd0;
    if (rst) f_lpend <= 1'b0;
    else if (f_fall) f_lpend <= 1'b1;
    else if (list_done) f_lpend <= 1'b0;
    f_lage <= (f_fall || !f_lpend) ? 3'd0 : (f_lage != 3'd7 ? f_lage + 3'd1 : f_lage);
end
always @(*) begin
    if (!f_past || rst) assume(!ctl_cam_held && !rect_busy && !list_done);
    if (f_past && !f_held_p && ctl_cam_held) assume(f_want_p && !f_rel_p);
    if (f_past && f_held_p && !f_rel_p && !f_rel_pp) assume(ctl_cam_held);
    if (f_past && f_rel_pp) assume(!ctl_cam_held);
    assume(f_hwait < F_H);
    if (f_past && !f_busy_p && rect_busy) assume(f_rs_p);
    if (f_past && (f_rs_p || f_rs_pp)) assume(rect_busy);
    assume(f_rlen < F_R);
    if (list_done) assume(f_lpend);
    if (f_lpend) assume(!f_fall);
    if (f_lpend && f_lage >= F_L - 1) assume(list_done);
end

// a pair taken since the last release (cam_held rose after it)
reg f_fresh = 1'b0;
always @(posedge clk)
    if (rst || ctl_cam_release) f_fresh <= 1'b0;
    else if (ctl_cam_held && !f_held_p) f_fresh <= 1'b1;

// ---- the session: from start (taken in IDLE) to busy low ---------------------------------------------------
// st: 0 IDLE, 1 ARM, 2 PAIR, 3 RSTART, 4 RFIRST, 5 RECT, 6 REL, 7 LISTS, 8 DRAIN (MyHDL's enum encoding)
reg f_more = 1'b0;                       // the session continues after its frame in progress
reg [4:0] f_quiet = 5'd0, f_end = 5'd0;  // clocks since the last rect_start / since the session is ending
reg [1:0] f_after = 2'd0;                // rect_starts since the session is ending
reg [31:0] f_ndone = 32'd0;              // list_done pulses since rst
always @(posedge clk)
    if (rst) begin
        f_more <= 1'b0;
        f_quiet <= 5'd0;
        f_end <= 5'd0;
        f_after <= 2'd0;
        f_ndone <= 32'd0;
    end else begin
        if (list_done) f_ndone <= f_ndone + 32'd1;
        if (st == 4'd0) begin
            f_more <= continuous;  // the block's precedence: a stop in the clock of start is not seen
            f_quiet <= 5'd0;
            f_end <= 5'd0;
            f_after <= 2'd0;
        end else begin
            if (stop) f_more <= 1'b0;
            f_quiet <= rect_start ? 5'd0 : (f_quiet != 5'd31 ? f_quiet + 5'd1 : f_quiet);
            if (!f_more || stop) f_end <= (f_end != 5'd31) ? f_end + 5'd1 : f_end;
            if ((!f_more || stop) && rect_start && f_after != 2'd3) f_after <= f_after + 2'd1;
        end
    end

always @(*) if (f_past && !rst) begin
    // no deadlock: progress within F_N clocks while busy; the end within F_M clocks once it is due
    if (st != 4'd0) assert(f_quiet < F_N);
    if (st != 4'd0) assert(f_end < F_M);
    assert(f_after <= 2'd1);
    // every rectified frame complete when the session ends
    if (st == 4'd0) assert(!f_lpend);
    // the pair's handshake with the rectifier
    if (rect_start) assert(f_held_p && f_fresh);
    if (ctl_cam_release) assert(f_held_p && !f_busy_p);
    // bookkeeping
    assert(pending == {1'b0, f_lpend});
    assert(nframes == f_ndone);
    assert(st <= 4'd8);
    if (st != 4'd0) assert(more == f_more);
end

// invariants (the state machine against the environment's state: they make the induction close)
always @(*) if (f_past && !rst) begin
    if (st == 4'd2) assert(ctl_cam_want);
    if (st == 4'd3) assert(rect_start && ctl_cam_want);
    if (st == 4'd4) assert(f_rs_p && ctl_cam_want);
    if (st == 4'd5) assert(f_busy_p && ctl_cam_want && f_held_p);
    if (st == 4'd6) assert(md && (ctl_cam_release || f_rel_p || f_rel_pp) && ctl_cam_want);
    if (st == 4'd7) assert(!md && f_lpend && !ctl_cam_want);
    if (st == 4'd8) assert(md && !ctl_cam_want);
    if (st == 4'd1) assert(!md);
    if (f_more) assert(f_end == 5'd0 && f_after == 2'd0);
    if (f_held_p) assert(f_fresh || f_rel_p || f_rel_pp);  // a pair held is a new one or being let go
    if (st == 4'd0 || st == 4'd1 || st == 4'd7 || st == 4'd8) assert(!f_fresh || ctl_cam_release);
    if (st == 4'd3 || st == 4'd4 || st == 4'd5) assert(f_held_p || ctl_cam_held);
end

// ---- covers --------------------------------------------------------------------------------------
reg [1:0] f_nrs = 2'd0;  // rect_starts in the session
always @(posedge clk) f_nrs <= (rst || st == 4'd0) ? 2'd0 : f_nrs + (rect_start && f_nrs != 2'd3);
always @(*) if (f_past && !rst) begin
    cover(st == 4'd7 && !md && f_nrs == 2'd2 && list_done);     // sequential: the 2nd frame's lists complete
    cover(st == 4'd8 && md && f_nrs == 2'd2 && list_done);      // overlapped: 2 frames, the last one's lists
    cover(st == 4'd5 && md && f_lpend);                         // overlapped: lists of one frame while the next is rectified
    cover(!busy && frames == 32'd1);                               // one frame complete, busy low
end
