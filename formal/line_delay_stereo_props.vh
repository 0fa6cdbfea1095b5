// Formal properties of line_delay on a stereo stream (formal/run.py includes this file into MyHDL's Verilog
// of the block, just before endmodule). Run with width=4, height=3 (4x3 frames per camera), data_width=2,
// stereo. One clock.
// Input obeys the stereo image-stream protocol of eyestereo.hdl.interfaces.stream (assumptions: left then
// right beat of each pixel, eol/eof on both beats, reset tokens of either cam anywhere, also between the
// two beats of a pixel, idle cycles anywhere) => the output obeys it (assertions), and each camera's output
// pixel (x, y) carries that camera's input pixel (x, y-1) for y >= 1.
localparam F_W = 4, F_H = 3;

reg f_past = 1'b0;
always @(posedge clk) f_past <= 1'b1;
// reset in the first cycle; the producer shares the reset (no beat while rst is high)
always @(*) begin
    if (!f_past) assume(rst);
    if (rst) assume(!sink_valid);
end

// ---- the input: a protocol model (which camera's beat and which pixel of the frame come next) ---------
reg [1:0] f_ix = 2'd0, f_iy = 2'd0;
reg f_icam = 1'b0;
wire f_ipix = sink_valid && (sink_eol || !sink_eof);
wire f_itok = sink_valid && sink_eof && !sink_eol;
always @(*) if (f_ipix) begin
    assume(sink_cam == f_icam);
    assume(sink_eol == (f_ix == F_W - 1));
    assume(sink_eof == (sink_eol && f_iy == F_H - 1));
end
always @(posedge clk)
    if (rst || f_itok) begin
        f_ix <= 2'd0;
        f_iy <= 2'd0;
        f_icam <= 1'b0;
    end else if (f_ipix) begin
        f_icam <= !f_icam;
        if (f_icam) begin
            f_ix <= (f_ix == F_W - 1) ? 2'd0 : f_ix + 2'd1;
            if (f_ix == F_W - 1) f_iy <= (f_iy == F_H - 1) ? 2'd0 : f_iy + 2'd1;
        end
    end

// ---- the output: the same model, asserted ----------------------------------------------------------
reg [1:0] f_ox = 2'd0, f_oy = 2'd0;
reg f_ocam = 1'b0;
wire f_opix = source_valid && (source_eol || !source_eof);
wire f_otok = source_valid && source_eof && !source_eol;
always @(posedge clk)
    if (rst || f_otok) begin
        f_ox <= 2'd0;
        f_oy <= 2'd0;
        f_ocam <= 1'b0;
    end else if (f_opix) begin
        f_ocam <= !f_ocam;
        if (f_ocam) begin
            f_ox <= (f_ox == F_W - 1) ? 2'd0 : f_ox + 2'd1;
            if (f_ox == F_W - 1) f_oy <= (f_oy == F_H - 1) ? 2'd0 : f_oy + 2'd1;
        end
    end
always @(*) if (f_past && f_opix) begin
    assert(source_cam == f_ocam);                           // left, right, left, ... from the frame's start
    assert(source_eol == (f_ox == F_W - 1));                // eol on both beats of a line's last pixel
    assert(source_eof == (source_eol && f_oy == F_H - 1));  // eof with it on both beats of the frame's last
end

// ---- the data: a column and a camera chosen by the solver, followed through the memory --------------
(* anyconst *) reg [1:0] f_col;
(* anyconst *) reg f_cam;
reg [1:0] f_val = 2'd0, f_prev = 2'd0;  // the last pixel written at (f_col, f_cam), the one before it
always @(posedge clk) if (f_ipix && f_ix == f_col && f_icam == f_cam) begin
    f_val <= sink_data;
    f_prev <= f_val;
end
always @(*) if (f_past && f_opix && f_ox == f_col && f_ocam == f_cam && f_oy != 2'd0)
    assert(source_data == f_prev);  // that camera's pixel (x, y-1)

// Invariants (they also make the induction close).
reg [1:0] f_ixd = 2'd0, f_iyd = 2'd0;  // where the input was one clock ago
reg f_icamd = 1'b0;
reg f_rst_p = 1'b1;
always @(posedge clk) begin
    f_ixd <= f_ix;
    f_iyd <= f_iy;
    f_icamd <= f_icam;
    f_rst_p <= rst;
end
always @(*) if (f_past) begin
    assert(col == f_ix);
    assert(mem[{f_col, f_cam}] == f_val);
    if (!f_rst_p) assert(f_ox == f_ixd && f_oy == f_iyd && f_ocam == f_icamd);
    if (f_rst_p) assert(!source_valid && f_ox == 2'd0 && f_oy == 2'd0 && !f_ocam);
    assert(f_ix < F_W && f_iy < F_H);
end

// ---- covers --------------------------------------------------------------------------------------
always @(*) begin
    cover(f_past && f_opix && source_eof && source_cam);               // a whole stereo frame's end at the output
    cover(f_past && f_opix && f_ox == f_col && f_ocam == f_cam && f_oy == 2'd2);  // the tagged pixel, last line
    cover(f_past && f_otok && f_ocam);                                 // a token between a pixel's two beats
end
