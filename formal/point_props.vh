// Formal properties of the point operations (cornerness, prethreshold): formal/run.py includes this file
// into MyHDL's Verilog of the block, just before endmodule, after a header with
//   localparam F_LAT = <the block's latency in clocks>;   and, for prethreshold, `define F_THRESHOLD.
// One clock, a free input (any beats, tokens, idle cycles; the protocol is not assumed: a point operation
// keeps no position, so protocol in => protocol out follows from the first property):
//   * the output beat (valid, eol, eof; cam on a stereo stream) is the input's of exactly F_LAT clocks
//     before, or no beat when rst came in between (every flag register is reset);
//   * nothing comes out after F_LAT idle clocks (nor in the F_LAT clocks after rst);
//   * prethreshold: an output pixel is the input pixel where that was greater than its block's threshold
//     (written through thr_we/thr_addr/thr_data, 0 after rst, signed), else 0. One block (blocks (1, 1)),
//     or, with `define F_BLOCKS, 2x2 frames in 2x2 blocks (then the input protocol is assumed).

reg f_past = 1'b0;
always @(posedge clk) f_past <= 1'b1;
always @(*) if (!f_past) assume(rst);

// ---- the reference: the input beat through F_LAT registers, each cleared by rst ------------------------
`ifdef F_STEREO
`define F_BEAT {sink_valid, sink_eol, sink_eof, sink_cam}
`define F_OUT {source_valid, source_eol, source_eof, source_cam}
localparam F_NB = 4;
`else
`define F_BEAT {sink_valid, sink_eol, sink_eof}
`define F_OUT {source_valid, source_eol, source_eof}
localparam F_NB = 3;
`endif
reg [F_NB*F_LAT-1:0] f_pipe = 0;  // stage i in bits [F_NB*i +: F_NB]; the last one is the output
always @(posedge clk) f_pipe <= rst ? 0 : {f_pipe, `F_BEAT};
// clocks since the last input beat or rst (saturating at F_LAT)
reg [3:0] f_idle = 4'd0;
always @(posedge clk)
    if (rst || sink_valid) f_idle <= 4'd0;
    else if (f_idle < F_LAT) f_idle <= f_idle + 4'd1;
always @(*) if (f_past) begin
    assert(`F_OUT == f_pipe[F_NB*(F_LAT-1) +: F_NB]);      // the input's beat, exactly F_LAT clocks later
    if (f_idle == F_LAT) assert(!source_valid);  // nothing while idle
end

`ifdef F_THRESHOLD
// ---- prethreshold: the thresholds' reference and the comparison, one clock ahead -----------------------
reg [19:0] f_thr;  // the threshold of the input pixel's block (0 until written after rst)
`ifdef F_BLOCKS
// 2x2 frames in 2x2 blocks (header `define F_BLOCKS): each pixel a block of its own, index 2 y + x. The
// input keeps the protocol here (assumed, as in line_delay_props.vh), so that it has a position.
reg f_ix = 1'b0, f_iy = 1'b0;
wire f_ipix = sink_valid && (sink_eol || !sink_eof);
wire f_itok = sink_valid && sink_eof && !sink_eol;
always @(*) begin
    if (rst) assume(!sink_valid);
    if (f_ipix) begin
        assume(sink_eol == f_ix);
        assume(sink_eof == (sink_eol && f_iy));
    end
end
always @(posedge clk)
    if (rst || f_itok) {f_iy, f_ix} <= 2'd0;
    else if (f_ipix) {f_iy, f_ix} <= {f_iy, f_ix} + 2'd1;
// the table as written, entry i in bits [20 i +: 20] (not reset: the flags say what was written since rst)
reg [79:0] f_tab = 80'd0;
reg [3:0] f_wr = 4'd0;
integer f_k;
always @(posedge clk) begin
    if (thr_we) f_tab[20 * thr_addr +: 20] <= thr_data;
    if (rst) f_wr <= 4'd0;
    else if (thr_we) f_wr[thr_addr] <= 1'b1;
end
always @(*) f_thr = f_wr[{f_iy, f_ix}] ? f_tab[20 * {f_iy, f_ix} +: 20] : 20'd0;
// invariants (they close the induction): the block position and the table agree with the reference
always @(*) if (f_past) begin
    assert(x == f_ix && y == f_iy && blk == {f_iy, f_ix});
    assert(block_position0_bx == f_ix && block_position0_by == f_iy && block_position0_base == {f_iy, 1'b0});
    assert(written == f_wr);
    for (f_k = 0; f_k < 4; f_k = f_k + 1) assert(mem[f_k] == f_tab[20 * f_k +: 20]);
end
`else
// one block (blocks (1, 1)): a register, 0 after rst
reg [19:0] f_glob = 20'd0;
always @(posedge clk)
    if (rst) f_glob <= 20'd0;
    else if (thr_we) f_glob <= thr_data;
always @(*) f_thr = f_glob;
always @(*) if (f_past) assert(global_threshold0_stored == f_glob);  // invariant (closes the induction)
`endif
reg f_pass = 1'b0;
reg [19:0] f_data = 20'd0;
reg [19:0] f_thr_p = 20'd0;
always @(posedge clk) begin
    f_pass <= $signed(sink_data) > $signed(f_thr);
    f_data <= sink_data;
    f_thr_p <= f_thr;
end
always @(*) if (f_past && source_valid) assert(source_data == (f_pass ? f_data : 20'd0));
`endif

// ---- covers ----------------------------------------------------------------------------------------------
always @(*) if (f_past) begin
    cover(source_valid && source_eol && source_eof);    // a frame end at the output
    cover(source_valid && source_eof && !source_eol);   // a reset token at the output
`ifdef F_THRESHOLD
    cover(source_valid && source_data != 20'd0);        // a pixel above its threshold passed
`ifdef F_BLOCKS
    cover(source_valid && source_eol && source_eof && f_thr_p != 20'd0 && !f_pass);  // block 3's used
`endif
    cover(source_valid && f_thr_p != 20'd0 && !f_pass);   // one at or below a written threshold cleared
`endif
end
