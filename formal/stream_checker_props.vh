// Formal properties of stream_checker (formal/run.py includes this file into MyHDL's Verilog of the block,
// just before endmodule). Run mono, width=4, height=3 (4x3 frames), data_width=2; repair off, or on with the
// header `define F_REPAIR (then the stream is not passed unchanged but repaired: the section at F_REPAIR). One clock.
// The input is free: any sequence of beats, idle cycles, reset tokens, lines and frames of any length.
// A reference checker written from the block's specification (the fault table of its docstring) follows
// the input from rst to its first fault; the properties say that the block agrees with it on every clock:
//   * a stream that keeps the protocol never raises `error` (no good frame is ever flagged);
//   * the first faulty beat raises `error` one clock later, with that fault's `code`, and both stay;
//   * the stream leaves unchanged, one clock later.
localparam F_W = 4, F_H = 3;

reg f_past = 1'b0;
always @(posedge clk) f_past <= 1'b1;
always @(*) if (!f_past) assume(rst);

// ---- the reference: the position in the frame, and the first fault --------------------------------
reg [1:0] f_x = 2'd0, f_y = 2'd0;
reg f_seen = 1'b0;        // a fault was seen since rst (the reference stops following the stream)
reg [2:0] f_code = 3'd0;  // its code
wire f_pix = sink_valid && (sink_eol || !sink_eof);  // a pixel beat (not a reset token)
wire f_tok = sink_valid && sink_eof && !sink_eol;    // a reset token: the next beat is pixel (0, 0)
reg [2:0] f_fault;        // the fault of this beat, by the docstring's table (0: none)
always @(*) begin
    f_fault = 3'd0;
    if (f_pix) begin
        if (f_x != F_W - 1) begin
            if (sink_eol) f_fault = 3'd2;                       // SHORT_LINE
        end else if (!sink_eol) f_fault = 3'd1;                 // LONG_LINE
        else if (f_y != F_H - 1) begin
            if (sink_eof) f_fault = 3'd4;                       // EARLY_EOF
        end else if (!sink_eof) f_fault = 3'd3;                 // MISSING_EOF
    end
end
always @(posedge clk)
    if (rst) begin
        f_x <= 2'd0; f_y <= 2'd0; f_seen <= 1'b0; f_code <= 3'd0;
    end else if (!f_seen) begin
        if (f_fault != 3'd0) begin
            f_seen <= 1'b1;
            f_code <= f_fault;
        end else if (f_tok) begin
            f_x <= 2'd0; f_y <= 2'd0;
        end else if (f_pix) begin
            f_x <= (f_x == F_W - 1) ? 2'd0 : f_x + 2'd1;
            if (f_x == F_W - 1) f_y <= (f_y == F_H - 1) ? 2'd0 : f_y + 2'd1;
        end
    end

// ---- the block agrees with the reference ----------------------------------------------------------
reg [1:0] f_data = 2'd0;
reg f_valid = 1'b0, f_eol = 1'b0, f_eof = 1'b0, f_rst_p = 1'b1;
always @(posedge clk) begin
    f_data <= sink_data;
    f_valid <= sink_valid && !rst;
    f_eol <= sink_eol && !rst;
    f_eof <= sink_eof && !rst;
    f_rst_p <= rst;
end
always @(*) if (f_past) begin
    assert(error == f_seen);           // never a good frame flagged; every first fault flagged
    assert(code == f_code);            // with its code, kept until rst
`ifndef F_REPAIR
    assert(source_valid == f_valid);   // the stream passes unchanged, one clock later
    if (source_valid) assert(source_eol == f_eol && source_eof == f_eof && source_data == f_data);
`endif
end

`ifdef F_REPAIR
// ---- repair on (header `define F_REPAIR): the source keeps the protocol, whatever the input ------------
// The output's position in its frame (line_delay_props.vh's protocol model), asserted: eol exactly on a
// line's width-th pixel, eof exactly on the frame's last; a reset token (the faulty beat) starts a frame.
reg [1:0] f_ox = 2'd0, f_oy = 2'd0;
wire f_opix = source_valid && (source_eol || !source_eof);
wire f_otok = source_valid && source_eof && !source_eol;
always @(posedge clk)
    if (rst || f_otok) begin
        f_ox <= 2'd0;
        f_oy <= 2'd0;
    end else if (f_opix) begin
        f_ox <= (f_ox == F_W - 1) ? 2'd0 : f_ox + 2'd1;
        if (f_ox == F_W - 1) f_oy <= (f_oy == F_H - 1) ? 2'd0 : f_oy + 2'd1;
    end
always @(*) if (f_past && f_opix) begin
    assert(source_eol == (f_ox == F_W - 1));
    assert(source_eof == (source_eol && f_oy == F_H - 1));
    assert(source_data == f_data);     // a pixel that leaves is the input's, one clock later
end
// Invariants (they make the induction close): the output is where the checker was one clock before
// while in sync, at a frame's start (after the token) while not.
reg [1:0] f_xd = 2'd0, f_yd = 2'd0;
reg f_syncd = 1'b1;
always @(posedge clk) begin
    f_xd <= x;
    f_yd <= y;
    f_syncd <= sync;
end
always @(*) if (f_past) begin
    if (f_rst_p) assert(!source_valid && f_ox == 2'd0 && f_oy == 2'd0);
    else if (f_syncd) assert(f_ox == f_xd && f_oy == f_yd);
    else assert(f_ox == 2'd0 && f_oy == 2'd0);
    assert(x < F_W && y < F_H && x_last == (x == F_W - 1) && y_last == (y == F_H - 1));
    assert(f_ox < F_W && f_oy < F_H);
end
always @(*) if (f_past) begin
    cover(f_otok && error);            // a broken frame cut short by a token
    cover(f_opix && source_eof && error);  // a whole frame after a broken one
end
`endif

// Invariants (they make the induction close): while no fault was seen, the block is in step with
// the reference.
always @(*) if (f_past && !f_seen) begin
    assert(sync);
    assert(x == f_x && y == f_y);
    assert(x_last == (f_x == F_W - 1) && y_last == (f_y == F_H - 1));
end
always @(*) if (f_past) assert(f_x < F_W && f_y < F_H && (f_seen == (f_code != 3'd0)));

// ---- covers: each fault reached, and a whole good frame ---------------------------------------------
reg f_frame = 1'b0;  // a good frame ended since rst
always @(posedge clk) if (rst) f_frame <= 1'b0; else if (!f_seen && f_pix && sink_eof && f_fault == 3'd0) f_frame <= 1'b1;
always @(*) if (f_past) begin
    cover(error && code == 3'd1);
    cover(error && code == 3'd2);
    cover(error && code == 3'd3);
    cover(error && code == 3'd4);
    cover(f_frame && !error);
    cover(f_frame && error && code == 3'd2);   // a good frame, then a short line
end
