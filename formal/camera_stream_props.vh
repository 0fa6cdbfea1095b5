// Formal properties of camera_stream (formal/run.py includes this file into MyHDL's Verilog of the block, just
// before endmodule). Run at width=2, height=2 (a line is 4 bytes, one pixel pair), order YUYV, VSYNC and HREF
// active high, no luma port. One clock, the camera's (cam_pclk).
// The bus is free: VSYNC, HREF and the data bytes take any values on any clock (lines of any length, VSYNC
// anywhere, a camera switched on mid-frame); rst in the first clock, then free (a reset at any time).
// A reference receiver written from the docstring and the camera bus rules (hdl/interfaces/camera_bus.py)
// follows the bus as the rising edge samples it:
//   * a frame begins with VSYNC; each line is 2 * width bytes under HREF, each pixel pair's 4 bytes (Y0 U Y1 V)
//     give the words {U, Y0} and {V, Y1}; the even word leaves with the edge after the pair's 4th byte is
//     sampled, the odd one with the next byte or, for a line's last pair, with the first blanking sample,
//     which carries eol (and eof on the frame's last line);
//   * a line too long, HREF dropped mid-line or a VSYNC before the last line aborts the frame: a reset token
//     if a word of it came out, then nothing until the next VSYNC; lines after the last one are ignored.
// Proven: the block's output beat (valid, eol, eof; data of pixel beats) is the reference's, one clock later;
// and, independently of the reference, the output keeps the image-stream protocol (eol exactly on a line's
// width-th pixel, eof exactly on the frame's last, a reset token starting a frame again), pixel beats at
// least 2 clocks apart, whatever the bus does.
localparam F_W = 2, F_H = 2, F_W2 = 2 * F_W;
// An undeclared name (e.g. a register MyHDL named otherwise) is an error, not an implicit 1-bit wire.
`default_nettype none

reg f_past = 1'b0;
always @(posedge cam_pclk) f_past <= 1'b1;
always @(*) if (!f_past) assume(rst);

// ---- the reference receiver -----------------------------------------------------------------------------
reg f_vs = 1'b0, f_hr = 1'b0;   // the bus as the edge samples it
reg [7:0] f_d = 8'd0;
always @(posedge cam_pclk) {f_vs, f_hr, f_d} <= {cam_vsync, cam_href, cam_data};
reg f_arm = 1'b0;               // a frame began with VSYNC, neither complete nor aborted
reg f_st = 1'b0;                // a word of it has come out
reg [2:0] f_n = 3'd0;           // bytes of the line so far
reg f_y = 1'b0;                 // complete lines
reg [7:0] f_y0 = 8'd0, f_u = 8'd0, f_y1 = 8'd0;  // the pair's first three bytes
reg [15:0] f_odd = 16'd0;       // the pair's odd word, due
// this sample's outcome
reg f_abort, f_ov, f_oeol, f_oeof;
reg [15:0] f_od;
always @(*) begin
    f_abort = 1'b0; f_ov = 1'b0; f_oeol = 1'b0; f_oeof = 1'b0; f_od = 16'd0;
    if (f_arm) begin
        if (f_vs) f_abort = f_y != 1'b0 || f_n != 3'd0;   // a VSYNC before the last line
        else if (f_hr) f_abort = f_n == F_W2;             // a line too long
        else f_abort = f_n != 3'd0 && f_n != F_W2;        // HREF dropped mid-line
    end
    if (f_abort) begin
        f_ov = f_st; f_oeof = f_st;                      // the token, if a word came out
    end else if (!f_vs && f_arm) begin
        if (f_hr) begin
            if (f_n[1:0] == 2'd3) begin f_ov = 1'b1; f_od = {f_u, f_y0}; end       // even word: {U, Y0}
            else if (f_n[1:0] == 2'd0 && f_n != 3'd0) begin f_ov = 1'b1; f_od = f_odd; end  // odd word
        end else if (f_n == F_W2) begin                                             // the line's end
            f_ov = 1'b1; f_oeol = 1'b1; f_oeof = f_y == F_H - 1; f_od = f_odd;
        end
    end
end
always @(posedge cam_pclk)
    if (rst) begin
        f_arm <= 1'b0; f_st <= 1'b0; f_n <= 3'd0; f_y <= 1'b0;
    end else if (f_vs) begin
        f_arm <= 1'b1; f_st <= 1'b0; f_n <= 3'd0; f_y <= 1'b0;
    end else if (f_abort) begin
        f_arm <= 1'b0; f_st <= 1'b0; f_n <= 3'd0;
    end else if (f_arm && f_hr) begin
        case (f_n[1:0])
        2'd0: f_y0 <= f_d;
        2'd1: f_u <= f_d;
        2'd2: f_y1 <= f_d;
        2'd3: begin f_odd <= {f_d, f_y1}; f_st <= 1'b1; end  // odd word: {V, Y1}
        endcase
        f_n <= f_n + 3'd1;
    end else if (f_arm && f_n != 3'd0) begin  // (f_n == F_W2: any other count aborted)
        f_n <= 3'd0;
        if (f_y == F_H - 1) begin f_arm <= 1'b0; f_st <= 1'b0; f_y <= 1'b0; end
        else f_y <= f_y + 1'b1;
    end
// the reference's beat, one clock later (none after rst)
reg f_rv = 1'b0, f_reol = 1'b0, f_reof = 1'b0, f_rpix = 1'b0;
reg [15:0] f_rd = 16'd0;
always @(posedge cam_pclk) begin
    f_rv <= f_ov && !rst; f_reol <= f_oeol; f_reof <= f_oeof; f_rd <= f_od;
    f_rpix <= f_ov && !rst && !f_abort;
end
always @(*) if (f_past) begin
    assert(source_valid == f_rv);
    if (source_valid) assert(source_eol == f_reol && source_eof == f_reof);
    if (f_rpix) assert(source_data == f_rd);   // a pixel's word (a token's data are unspecified)
end

// ---- the output keeps the protocol, whatever the bus ---------------------------------------------------------
reg f_ox = 1'b0, f_oy = 1'b0;
wire f_opix = source_valid && (source_eol || !source_eof);
wire f_otok = source_valid && source_eof && !source_eol;
always @(posedge cam_pclk)
    if (rst || f_otok) {f_oy, f_ox} <= 2'd0;
    else if (f_opix) begin
        f_ox <= (f_ox == F_W - 1) ? 1'b0 : f_ox + 1'b1;
        if (f_ox == F_W - 1) f_oy <= (f_oy == F_H - 1) ? 1'b0 : f_oy + 1'b1;
    end
reg f_opix_p = 1'b0;
always @(posedge cam_pclk) f_opix_p <= f_opix;
always @(*) if (f_past && f_opix) begin
    assert(source_eol == (f_ox == F_W - 1));
    assert(source_eof == (source_eol && f_oy == F_H - 1));
end

// ---- invariants (they close the induction) -------------------------------------------------------------------
// the output model's position after this clock's beat
wire f_ox_n = (rst || f_otok) ? 1'b0 : (f_opix ? ((f_ox == F_W - 1) ? 1'b0 : f_ox + 1'b1) : f_ox);
wire f_oy_n = (rst || f_otok) ? 1'b0 : ((f_opix && f_ox == F_W - 1) ? ((f_oy == F_H - 1) ? 1'b0 : f_oy + 1'b1) : f_oy);
always @(*) if (f_past) begin
    assert(vs_r == f_vs && hr_r == f_hr && d_r == f_d);
    assert(armed == f_arm && started == f_st && n == f_n && y == f_y && f_n <= F_W2);
    if (f_arm && f_n[1:0] >= 2'd1) assert(b0 == f_y0);
    if (f_arm && f_n[1:0] >= 2'd2) assert(b1 == f_u);
    if (f_arm && f_n[1:0] == 2'd3) assert(b2 == f_y1);
    if (f_arm && f_n != 3'd0 && f_n[1:0] == 2'd0) assert(pend == f_odd);
    // the output is where the reference's frame is: the line, and the pair's even word out while its odd
    // one is due (a line of one pair); at a frame's start when none of the frame came out
    if (f_arm) assert(f_st == (f_y != 1'b0 || f_n == F_W2));  // a line of one pair: a word out per line begun
    else assert(!f_st && f_n == 3'd0);
    if (rst) ;  // (everything starts again)
    else if (f_arm && f_st) assert(f_oy_n == f_y && f_ox_n == (f_n == F_W2));
    else assert(f_ox_n == 1'b0 && f_oy_n == 1'b0);
end

// ---- covers ---------------------------------------------------------------------------------------------------
always @(*) if (f_past) begin
    cover(f_opix && source_eof);               // a whole frame out
    cover(f_otok);                             // a broken frame's token
    cover(f_opix && f_opix_p);                 // two pixel beats in consecutive clocks
    cover(f_opix && source_eof && f_rd == 16'hA55A);  // ... with a chosen word
end
