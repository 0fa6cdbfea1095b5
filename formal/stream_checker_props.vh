// Formal properties of stream_checker (formal/run.py includes this file into MyHDL's Verilog of the block,
// just before endmodule). Run at width=4, height=3 (4x3 frames), data_width=2; mono, or stereo with the header
// `define F_STEREO; repair off, or on with the header `define F_REPAIR (then the stream is not passed
// unchanged but repaired: the section at F_REPAIR). One clock.
// The input is free: any sequence of beats, idle cycles, reset tokens (of either camera), lines and frames of
// any length, any camera order.
// A reference checker written from the block's specification (the fault table and the recovery rule of its
// docstring) follows the input from rst: its position (camera, x, y), whether it is in sync, and the first
// fault since rst. The properties say that the block agrees with it on every clock:
//   * a stream that keeps the protocol never raises `error` (no good frame is ever flagged);
//   * the first faulty beat raises `error` one clock later, with that fault's `code`, and both stay;
//   * repair off: the stream leaves unchanged, one clock later; repair on: the output beat is the
//     reference's (the faulty beat as a reset token, the beats up to the recovery point dropped), and
//     the output keeps the (stereo) protocol.
// An undeclared name (e.g. a register MyHDL named otherwise) is an error, not an implicit 1-bit wire.
`default_nettype none
localparam F_W = 4, F_H = 3;
`ifdef F_STEREO
localparam F_ST = 1'b1;
wire f_icam = sink_cam;
`else
localparam F_ST = 1'b0;
wire f_icam = 1'b0;
`endif

reg f_past = 1'b0;
always @(posedge clk) f_past <= 1'b1;
always @(*) if (!f_past) assume(rst);

// ---- the reference: the position in the frame, sync, and the first fault ---------------------------
reg [1:0] f_x = 2'd0, f_y = 2'd0;
reg f_ph = 1'b0;          // stereo: the right camera's beat of pixel (x, y) is due
reg f_sync = 1'b1;        // checking (no fault since the last recovery point)
reg f_seen = 1'b0;        // a fault was seen since rst
reg [2:0] f_code = 3'd0;  // the first one's code
wire f_pix = sink_valid && (sink_eol || !sink_eof);  // a pixel beat (not a reset token)
wire f_tok = sink_valid && sink_eof && !sink_eol;    // a reset token: the next beat is pixel (0, 0), left
wire f_xl = (f_x == F_W - 1), f_yl = (f_y == F_H - 1);
reg [2:0] f_fault;        // the fault of this beat at the reference's position, by the docstring's table
always @(*) begin
    f_fault = 3'd0;
    if (f_pix) begin
        if (F_ST && f_icam != f_ph) f_fault = 3'd5;             // STEREO: a beat of the wrong camera
        else if (F_ST && f_ph) begin                            // the right beat: its flags must be the left's,
            if (sink_eol != f_xl || sink_eof != (f_xl && f_yl)) f_fault = 3'd5;  // which were right
        end else if (!f_xl) begin
            if (sink_eol) f_fault = 3'd2;                       // SHORT_LINE
        end else if (!sink_eol) f_fault = 3'd1;                 // LONG_LINE
        else if (!f_yl) begin
            if (sink_eof) f_fault = 3'd4;                       // EARLY_EOF
        end else if (!sink_eof) f_fault = 3'd3;                 // MISSING_EOF
    end
end
wire f_bad = f_pix && f_sync && f_fault != 3'd0;   // the faulty beat
wire f_good = f_pix && f_sync && f_fault == 3'd0;  // a pixel beat in order
// an end-of-frame beat (stereo: the right camera's): out of sync (or faulty itself) it ends the broken frame
wire f_end = sink_valid && sink_eof && sink_eol && (!F_ST || f_icam);
always @(posedge clk)
    if (rst) begin
        f_x <= 2'd0; f_y <= 2'd0; f_ph <= 1'b0; f_sync <= 1'b1; f_seen <= 1'b0; f_code <= 3'd0;
    end else begin
        if (f_bad) begin
            f_seen <= 1'b1;
            if (!f_seen) f_code <= f_fault;
        end
        if (f_tok || ((f_bad || !f_sync) && f_end)) begin  // recovery: checking again from pixel (0, 0)
            f_x <= 2'd0; f_y <= 2'd0; f_ph <= 1'b0; f_sync <= 1'b1;
        end else if (f_bad) f_sync <= 1'b0;
        else if (f_good) begin
            if (F_ST && !f_ph) f_ph <= 1'b1;                   // the left beat: the right one is due
            else begin
                f_ph <= 1'b0;
                f_x <= f_xl ? 2'd0 : f_x + 2'd1;
                if (f_xl) f_y <= f_yl ? 2'd0 : f_y + 2'd1;
            end
        end
    end

// ---- the block agrees with the reference ----------------------------------------------------------
reg [1:0] f_data = 2'd0;
reg f_valid = 1'b0, f_eol = 1'b0, f_eof = 1'b0, f_cam = 1'b0, f_rst_p = 1'b1;
reg f_rvalid = 1'b0, f_reol = 1'b0, f_reof = 1'b0;  // the reference's repaired beat
always @(posedge clk) begin
    f_data <= sink_data;
    f_valid <= sink_valid && !rst;
    f_eol <= sink_eol && !rst;
    f_eof <= sink_eof && !rst;
    f_cam <= f_icam && !rst;
    f_rst_p <= rst;
    f_rvalid <= sink_valid && !rst && !(f_pix && !f_sync);  // out of sync a pixel beat is dropped
    f_reol <= sink_eol && !rst && !f_bad;                   // the faulty beat leaves as a token
    f_reof <= (sink_eof || f_bad) && !rst;
end
always @(*) if (f_past) begin
    assert(error == f_seen);           // never a good frame flagged; every first fault flagged
    assert(code == f_code);            // with its code, kept until rst
`ifndef F_REPAIR
    assert(source_valid == f_valid);   // the stream passes unchanged, one clock later
    if (source_valid) assert(source_eol == f_eol && source_eof == f_eof && source_data == f_data);
`else
    assert(source_valid == f_rvalid);  // the repaired stream: the reference's beats, one clock later
    if (source_valid) assert(source_eol == f_reol && source_eof == f_reof && source_data == f_data);
`endif
`ifdef F_STEREO
    if (source_valid) assert(source_cam == f_cam);  // the camera passes, one clock later
`endif
end

`ifdef F_REPAIR
// ---- repair on (header `define F_REPAIR): the source keeps the protocol, whatever the input ------------
// The output's position in its frame (line_delay_props.vh's protocol model), asserted: eol exactly on a
// line's width-th pixel, eof exactly on the frame's last, stereo: left then right beat of each pixel with
// the same flags; a reset token (the faulty beat) starts a frame.
reg [1:0] f_ox = 2'd0, f_oy = 2'd0;
reg f_oph = 1'b0;
wire f_opix = source_valid && (source_eol || !source_eof);
wire f_otok = source_valid && source_eof && !source_eol;
always @(posedge clk)
    if (rst || f_otok) begin
        f_ox <= 2'd0;
        f_oy <= 2'd0;
        f_oph <= 1'b0;
    end else if (f_opix) begin
        if (F_ST && !f_oph) f_oph <= 1'b1;
        else begin
            f_oph <= 1'b0;
            f_ox <= (f_ox == F_W - 1) ? 2'd0 : f_ox + 2'd1;
            if (f_ox == F_W - 1) f_oy <= (f_oy == F_H - 1) ? 2'd0 : f_oy + 2'd1;
        end
    end
always @(*) if (f_past && f_opix) begin
    assert(source_eol == (f_ox == F_W - 1));
    assert(source_eof == (source_eol && f_oy == F_H - 1));
    assert(source_data == f_data);     // a pixel that leaves is the input's, one clock later
`ifdef F_STEREO
    assert(source_cam == f_oph);       // left, then right
`endif
end
`ifndef F_OBS_ONLY
// Invariants (they make the induction close): the output is where the checker was one clock before
// while in sync, at a frame's start (after the token) while not.
reg [1:0] f_xd = 2'd0, f_yd = 2'd0;
reg f_syncd = 1'b1, f_phd = 1'b0;
always @(posedge clk) begin
    f_xd <= x;
    f_yd <= y;
    f_syncd <= sync;
`ifdef F_STEREO
    f_phd <= phase;
`endif
end
always @(*) if (f_past) begin
    if (f_rst_p) assert(!source_valid && f_ox == 2'd0 && f_oy == 2'd0 && !f_oph);
    else if (f_syncd) assert(f_ox == f_xd && f_oy == f_yd && f_oph == f_phd);
    else assert(f_ox == 2'd0 && f_oy == 2'd0 && !f_oph);
    assert(x < F_W && y < F_H && x_last == (x == F_W - 1) && y_last == (y == F_H - 1));
    assert(f_ox < F_W && f_oy < F_H);
end
`endif
always @(*) if (f_past) begin
    cover(f_otok && error);            // a broken frame cut short by a token
    cover(f_opix && source_eof && error);  // a whole frame after a broken one
`ifdef F_STEREO
    cover(f_opix && source_eof && source_cam && error);  // ... its last (right) beat
    cover(f_otok && error && f_oph);   // a token between a pixel's left and right beats (a faulty right beat)
`endif
end
`endif

`ifndef F_OBS_ONLY  // (header `define F_OBS_ONLY: the observable properties only, to see a mutant break one)
// Invariants (they make the induction close): the block follows the reference's position and sync on
// every clock (out of sync both keep the position they had; the recovery resets both).
always @(*) if (f_past) begin
    assert(sync == f_sync);
    assert(x == f_x && y == f_y);
    assert(x_last == f_xl && y_last == f_yl);
`ifdef F_STEREO
    assert(phase == f_ph);
    if (f_sync && f_ph) assert(left_eol == f_xl && left_eof == (f_xl && f_yl));
`endif
    assert(f_x < F_W && f_y < F_H && (f_seen == (f_code != 3'd0)));
    if (!F_ST) assert(!f_ph);
end
`endif

// ---- covers: each fault reached, and a whole good frame ---------------------------------------------
reg f_frame = 1'b0;  // a good frame ended since rst
always @(posedge clk)
    if (rst) f_frame <= 1'b0;
    else if (!f_seen && f_good && f_end) f_frame <= 1'b1;
reg f_again = 1'b0;  // a good frame ended after a fault (checking resumed after the recovery)
always @(posedge clk)
    if (rst) f_again <= 1'b0;
    else if (f_seen && f_good && f_end) f_again <= 1'b1;
always @(*) if (f_past) begin
    cover(error && code == 3'd1);
    cover(error && code == 3'd2);
    cover(error && code == 3'd3);
    cover(error && code == 3'd4);
    cover(f_frame && !error);
    cover(f_frame && error && code == 3'd2);   // a good frame, then a short line
    cover(f_again);                            // a fault, the recovery, a good frame
`ifdef F_STEREO
    cover(error && code == 3'd5 && f_frame);   // a good stereo frame, then a broken interleaving
    cover(f_past && f_sync && f_ph && sink_valid && sink_cam && sink_eol != f_xl);  // a pair that disagrees
    cover(f_past && f_sync && f_ph && f_tok);  // a token between a pixel's two beats
`endif
end
