// Formal properties of the window filters (sobel, nms 3x3/5x5, harris_window, convolve: every block whose
// border control is hdl/streaming/window.py's window_control). formal/run.py includes this file into MyHDL's
// Verilog of the block, just before endmodule, after the job's localparams and defines:
//   F_W, F_H    frame size (pixels per line, lines)
//   F_LEAD      pixels (of each camera) the output runs behind the input: r * width + r (nms 3x3 stereo: width + 2)
//   F_LAT       window_control's latency: clocks from its decision (at its sink beat) to the source beat
//   F_PRE       clocks from the block's sink to window_control's sink (harris_window: its product stage)
//   F_ST        1 on a stereo stream (left and right beat of each pixel), else 0
//   F_SHARE     stereo: the tail's beat spacing in clocks (the input's beats are assumed as far apart)
//   `F_ICAM, `F_OCAM   sink_cam / source_cam on a stereo stream, 1'b0 on a mono one
// and the wires f_skip, f_tail, f_wox, f_woy, f_wv0, f_wl0, f_wf0, f_wc0, f_half: window_control's registers
// (MyHDL's names: window_control0_skip, ... or nms3_one_delay0_window_control0_skip, ...; f_wc0 is 1 and
// f_half 0 on a mono stream).
// One clock. Input obeys the image-stream protocol (assumptions) => the output obeys it, frame for frame
// (assertions). Data values are not looked at (the benches compare them with the numpy models).
localparam F_B = F_ST ? 2 : 1;       // beats per pixel
localparam F_N = F_W * F_H * F_B;    // beats per frame
localparam F_L = F_LEAD * F_B;       // the lead in beats: window_control's skip / tail unit
localparam F_D = F_PRE + F_LAT;      // clocks from a sink beat to its source beat
localparam F_IDLE = F_PRE + F_L * F_SHARE + F_LAT;  // clocks after the last input beat with output possible

reg f_past = 1'b0;
always @(posedge clk) f_past <= 1'b1;
// reset in the first cycle; the producer shares the reset (no beat while rst is high)
always @(*) begin
    if (!f_past) assume(rst);
    if (rst) assume(!sink_valid);
end

// ---- the input: a protocol model (which camera's beat and which pixel of the frame come next) ---------
reg [7:0] f_ix = 8'd0, f_iy = 8'd0;
reg f_icam = 1'b0;
wire f_ipix = sink_valid && (sink_eol || !sink_eof);
wire f_itok = sink_valid && sink_eof && !sink_eol;
wire f_iend = f_ipix && sink_eof && (`F_ICAM || !F_ST);  // the frame's last beat
always @(*) if (f_ipix) begin
    assume(`F_ICAM == f_icam);
    assume(sink_eol == (f_ix == F_W - 1));
    assume(sink_eof == (sink_eol && f_iy == F_H - 1));
end
always @(posedge clk)
    if (rst || f_itok) begin
        f_ix <= 8'd0;
        f_iy <= 8'd0;
        f_icam <= 1'b0;
    end else if (f_ipix) begin
        f_icam <= F_ST ? !f_icam : 1'b0;
        if (f_icam || !F_ST) begin
            f_ix <= (f_ix == F_W - 1) ? 8'd0 : f_ix + 8'd1;
            if (f_ix == F_W - 1) f_iy <= (f_iy == F_H - 1) ? 8'd0 : f_iy + 8'd1;
        end
    end
// stereo with share > 1: the producer's beats (tokens too) come at least F_SHARE clocks apart
reg [7:0] f_igap = 8'd255;  // clocks since the last input beat (saturating)
always @(posedge clk)
    if (rst) f_igap <= 8'd255;
    else if (sink_valid) f_igap <= 8'd1;
    else if (f_igap != 8'd255) f_igap <= f_igap + 8'd1;
always @(*) if (sink_valid) assume(f_igap >= F_SHARE);

// ---- the same stream at window_control's sink (F_PRE clocks later): beats of the frame received ------
reg [F_PRE:0] f_pix_d = 0, f_tok_d = 0, f_end_d = 0;  // bit j: the sink's event j clocks ago
always @(*) begin
    f_pix_d[0] = f_ipix;
    f_tok_d[0] = f_itok;
    f_end_d[0] = f_iend;
end
generate if (F_PRE > 0) begin : f_pre
    always @(posedge clk)
        if (rst) begin
            f_pix_d[F_PRE:1] <= 0;
            f_tok_d[F_PRE:1] <= 0;
            f_end_d[F_PRE:1] <= 0;
        end else begin
            f_pix_d[F_PRE:1] <= f_pix_d[F_PRE - 1:0];
            f_tok_d[F_PRE:1] <= f_tok_d[F_PRE - 1:0];
            f_end_d[F_PRE:1] <= f_end_d[F_PRE - 1:0];
        end
end endgenerate
wire f_wpix = f_pix_d[F_PRE], f_wtok = f_tok_d[F_PRE], f_wend = f_end_d[F_PRE];
reg [7:0] f_wp = 8'd0;  // beats of the current frame window_control has taken
always @(posedge clk)
    if (rst || f_wtok || f_wend) f_wp <= 8'd0;
    else if (f_wpix) f_wp <= f_wp + 8'd1;

// ---- the output: the protocol model, asserted --------------------------------------------------------
reg [7:0] f_ox = 8'd0, f_oy = 8'd0;
reg f_ocam = 1'b0;
wire f_opix = source_valid && (source_eol || !source_eof);
wire f_otok = source_valid && source_eof && !source_eol;
wire f_oend = f_opix && source_eof && (`F_OCAM || !F_ST);
always @(posedge clk)
    if (rst || f_otok) begin
        f_ox <= 8'd0;
        f_oy <= 8'd0;
        f_ocam <= 1'b0;
    end else if (f_opix) begin
        f_ocam <= F_ST ? !f_ocam : 1'b0;
        if (f_ocam || !F_ST) begin
            f_ox <= (f_ox == F_W - 1) ? 8'd0 : f_ox + 8'd1;
            if (f_ox == F_W - 1) f_oy <= (f_oy == F_H - 1) ? 8'd0 : f_oy + 8'd1;
        end
    end
always @(*) if (f_past && f_opix) begin
    assert(`F_OCAM == f_ocam);                              // stereo: left, right, left, ... from a frame's start
    assert(source_eol == (f_ox == F_W - 1));                // eol on (both beats of) the width-th pixel
    assert(source_eof == (source_eol && f_oy == F_H - 1));  // eof on (both beats of) the frame's last pixel
end
// a reset token comes out F_D clocks after one went in (share 1: exactly; share > 1: window_control may hold
// it up to F_SHARE - 1 clocks for the spacing), exactly once, and no token else (rst clears both)
localparam F_DT = F_D + F_SHARE - 1;  // the latest clock a token comes out
reg [F_DT:0] f_tok_in = 0;  // bit j: a token went in j clocks ago
always @(*) f_tok_in[0] = f_itok;
always @(posedge clk)
    if (rst) f_tok_in[F_DT:1] <= 0;
    else f_tok_in[F_DT:1] <= f_tok_in[F_DT - 1:0];
// tokens in come at least F_SHARE clocks apart, so the window [F_D, F_DT] holds at most one; f_tok_out: the
// token of that window has come out
reg f_tok_out = 1'b0;
always @(posedge clk)
    if (rst) f_tok_out <= 1'b0;
    else if (f_tok_in[F_DT] || (f_tok_in[F_DT - 1 -: F_SHARE] == 0)) f_tok_out <= 1'b0;
    else if (f_otok) f_tok_out <= 1'b1;
always @(*) if (f_past) begin
    if (f_otok) assert(f_tok_in[F_DT -: F_SHARE] != 0 && !f_tok_out);  // a token in its window, once
    if (f_tok_in[F_DT]) assert(f_otok || f_tok_out);                  // ... and not later than F_DT
end
// stereo: every output beat, a reset token too, comes at least F_SHARE clocks after the beat before (the
// time-shared stage behind relies on it; before window_control held tokens, a token that came in the clock
// after a tail beat went out in the next clock: found by this job, see docs/formal.md)
reg [7:0] f_ogap = 8'd255;
always @(posedge clk)
    if (rst) f_ogap <= 8'd255;
    else if (source_valid) f_ogap <= 8'd1;
    else if (f_ogap != 8'd255) f_ogap <= f_ogap + 8'd1;
always @(*) if (f_past && source_valid) assert(f_ogap >= F_SHARE);
// nothing comes out of an idle block beyond the tail: F_IDLE clocks after the last input beat, no output
always @(*) if (f_past && f_igap != 8'd255 && f_igap > F_IDLE) assert(!source_valid);
always @(*) if (f_past && f_igap == 8'd255) assert(!source_valid);

// ---- frames: each input frame gives one output frame (of the same size: the model above), unless a -----
// reset token cuts its tail (then the token comes out); none without an input frame. A frame's output ends
// F_L tail beats (F_SHARE clocks each) and F_D clocks after its input: on a frame shorter than that (3x3
// frames at latency 6) the next frame's input, back to back, can end first, so two frames may be pending.
localparam F_PMAX = (F_N * F_SHARE < F_L * F_SHARE + F_D) ? 2 : 1;
reg [1:0] f_pend = 2'd0;  // input frames ended whose output frame has not
always @(posedge clk)
    if (rst || f_otok) f_pend <= f_iend ? 2'd1 : 2'd0;
    else f_pend <= f_pend + (f_iend ? 2'd1 : 2'd0) - (f_oend ? 2'd1 : 2'd0);
always @(*) if (f_past) begin
    assert(f_pend <= F_PMAX);
    if (f_oend) assert(f_pend != 2'd0 || f_iend);
end

// ---- invariants: window_control's counters against the models (they make the induction close) ---------
wire [7:0] f_qpix = f_woy * F_W + f_wox;  // pixels of its output frame emitted
// the camera of window_control's next beat, and the output position F_LAT clocks later
wire f_wcam = (f_tail != 0) ? f_half : (F_ST && f_wp >= F_L) ? ((f_wp - F_L) & 1) : 1'b0;
reg [F_LAT * 17 - 1:0] f_qd = 0;  // (cam, oy, ox) of window_control, 1 .. F_LAT clocks ago
always @(posedge clk)
    if (rst) f_qd <= 0;
    else f_qd <= {f_qd, f_wcam, f_woy, f_wox};
wire [16:0] f_qo = f_qd[F_LAT * 17 - 1 -: 17];
// frame ends between window_control and the source
reg [F_LAT - 1:0] f_wend_o = 0;
wire f_wc_end = f_wv0 && f_wl0 && f_wf0 && f_wc0;
always @(posedge clk)
    if (rst) f_wend_o <= 0;
    else f_wend_o <= {f_wend_o, f_wc_end};
// a frame whose tail a token cut: it is pending until that token comes out
reg f_cut = 1'b0;
always @(posedge clk)
    if (rst || f_otok) f_cut <= 1'b0;
    else if (f_wtok && f_tail != 0) f_cut <= 1'b1;
function [3:0] f_ones(input [15:0] v);
    integer i;
    begin
        f_ones = 0;
        for (i = 0; i < 16; i = i + 1) f_ones = f_ones + v[i];
    end
endfunction
always @(*) if (f_past) begin
    assert(f_wp < F_N);
    // window_control's count is the input model's, F_PRE clocks late (the beats on their way added)
    if ((f_tok_d >> 1) == 0)
        assert((f_wp + f_ones(f_pix_d >> 1)) % F_N == ((f_iy * F_W + f_ix) * F_B + f_icam) % F_N);
    assert(f_ix < F_W && f_iy < F_H && f_ox < F_W && f_oy < F_H && f_wox < F_W && f_woy < F_H);
    assert(f_skip == ((f_wp >= F_L) ? 0 : F_L - f_wp));
    assert(f_tail <= F_L);
    if (f_tail == 0) assert(f_qpix == ((f_wp >= F_L) ? (f_wp - F_L) / F_B : 0));
    if (f_tail != 0) begin
        assert(f_qpix == (F_N - f_tail) / F_B);
        assert(f_wp + f_tail <= F_L);
    end
    if (F_ST && f_tail == 0) assert(!f_half);
    if (F_ST && f_tail != 0) assert(f_half == ((F_N - f_tail) & 1));
    // (share > 1: not while a token window_control held is on its way: the control's position is already
    // reset, the output's is reset by the token)
    if ((f_tok_in >> (F_D + 1)) == 0 || f_tok_out) assert({f_ocam, f_oy, f_ox} == f_qo);
    assert(f_pend == f_ones(f_end_d >> 1) + (f_tail != 0) + f_ones({f_wend_o[F_LAT - 2:0], f_wc_end}) + f_cut);
    if (f_cut) assert(f_tail == 0 && (f_tok_in >> (F_PRE + 1)) != 0);
end

// ---- covers --------------------------------------------------------------------------------------
always @(*) begin
    cover(f_past && f_oend);                          // an output frame's end
    cover(f_past && f_otok);                          // a reset token passed
    cover(f_past && f_oend && f_pend == 2'd1 && f_itok);  // a frame's end out while a token comes in
end
