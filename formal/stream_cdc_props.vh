// Formal properties of stream_cdc (formal/run.py includes this file into MyHDL's Verilog of the block,
// just before endmodule). Run stereo, data_width=2, depth=4, frames of 2x2 pixels (8 beats). Model:
// multiclock on: wclk and rclk are free inputs (any ratio, any phase, edges at the same instant); inputs
// change only with their clock's rising edge. Both resets are high from the start until their clock has
// risen once, low afterwards (the reset behaviour mid-stream is async_fifo's job, proven there).
// Assumed: the sink keeps the stereo image-stream protocol (left then right beat of each pixel, eol/eof
// on both beats, reset tokens of either cam anywhere, idle cycles anywhere) and numbers its pixel beats:
// data = beats since the frame's start, modulo 4. Asserted on the read side:
//   * the output keeps the stereo protocol: cam alternates left/right from each frame start, eol on both
//     beats of every 2nd pixel, eof with them on the frame's last (whole stereo frames, or a reset token);
//   * no beat lost, duplicated or reordered inside a frame: every output pixel's data is its own beat
//     number in the output frame.
localparam F_W = 2, F_H = 2;

reg f_past = 1'b0;
always @($global_clock) f_past <= 1'b1;
reg f_wclk_p = 1'b0, f_rclk_p = 1'b0;
reg [5:0] f_win_p = 6'd0;
reg f_rin_p = 1'b0;
always @($global_clock) begin
    f_wclk_p <= wclk;
    f_rclk_p <= rclk;
    f_win_p <= {wrst, sink_valid, sink_eol, sink_eof, sink_cam, 1'b0};
    f_rin_p <= rrst;
end
wire f_wrose = f_past && wclk && !f_wclk_p;
wire f_rrose = f_past && rclk && !f_rclk_p;
reg [1:0] f_sdata_p = 2'd0;
always @($global_clock) f_sdata_p <= sink_data;
// inputs synchronous to their clock
always @($global_clock) if (f_past) begin
    if (!f_wrose) assume({wrst, sink_valid, sink_eol, sink_eof, sink_cam, 1'b0} == f_win_p && sink_data == f_sdata_p);
    if (!f_rrose) assume(rrst == f_rin_p);
end
// resets: high until the clock's first rising edge has passed, then low
reg f_wdone = 1'b0, f_rdone = 1'b0;  // the reset has been applied at a clock edge
always @(posedge wclk) if (wrst) f_wdone <= 1'b1;
always @(posedge rclk) if (rrst) f_rdone <= 1'b1;
always @(*) begin
    assume(wrst == !f_wdone);
    assume(rrst == !f_rdone);
end
always @(*) if (wrst) assume(!sink_valid);

// ---- the sink: the stereo protocol and the beat numbers (assumed) ------------------------------------
reg f_ix = 1'b0, f_iy = 1'b0, f_icam = 1'b0;
reg [1:0] f_iseq = 2'd0;
wire f_ipix = sink_valid && (sink_eol || !sink_eof);
wire f_itok = sink_valid && sink_eof && !sink_eol;
always @(*) if (f_ipix) begin
    assume(sink_cam == f_icam);
    assume(sink_eol == (f_ix == F_W - 1));
    assume(sink_eof == (sink_eol && f_iy == F_H - 1));
    assume(sink_data == f_iseq);
end
always @(posedge wclk)
    if (wrst || f_itok || (f_ipix && sink_eof && sink_cam)) begin
        f_ix <= 1'b0; f_iy <= 1'b0; f_icam <= 1'b0; f_iseq <= 2'd0;
    end else if (f_ipix) begin
        f_icam <= !f_icam;
        f_iseq <= f_iseq + 2'd1;
        if (f_icam) begin
            f_ix <= !f_ix;
            if (f_ix) f_iy <= !f_iy;
        end
    end

// ---- the source: the same, asserted -------------------------------------------------------------------
reg f_ox = 1'b0, f_oy = 1'b0, f_ocam = 1'b0;
reg [1:0] f_oseq = 2'd0;
wire f_opix = source_valid && (source_eol || !source_eof);
wire f_otok = source_valid && source_eof && !source_eol;
always @(posedge rclk)
    if (rrst || f_otok || (f_opix && source_eof && source_cam)) begin
        f_ox <= 1'b0; f_oy <= 1'b0; f_ocam <= 1'b0; f_oseq <= 2'd0;
    end else if (f_opix) begin
        f_ocam <= !f_ocam;
        f_oseq <= f_oseq + 2'd1;
        if (f_ocam) begin
            f_ox <= !f_ox;
            if (f_ox) f_oy <= !f_oy;
        end
    end
always @(*) if (f_past && f_rdone && !rrst && f_opix) begin
    assert(source_cam == f_ocam);                          // left, right, left, ... from the frame's start
    assert(source_eol == (f_ox == F_W - 1));               // eol on both beats of a line's last pixel
    assert(source_eof == (source_eol && f_oy == F_H - 1)); // eof with it on the frame's last
    assert(source_data == f_oseq);                         // no beat lost, duplicated or reordered
end

// ---- covers --------------------------------------------------------------------------------------
always @(*) if (f_past) begin
    cover(f_opix && source_eol && source_cam);             // a whole stereo line crossed
    cover(f_otok);                                         // a reset token crossed
end
