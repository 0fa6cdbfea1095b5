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
//     or, with `define F_BLOCKS, 2x2 frames in 2x2 blocks (then the input protocol is assumed; the table is
//     read a clock ahead, so a write counts from the second clock after it, and a reset token is compared
//     with the threshold of the beat due: its position's, on a stereo stream the camera due).
// Stereo (header `define F_STEREO): cam is a flag like eol and eof (it passes at the latency); prethreshold's
// thresholds are per camera (thr_addr = 2 * block + cam: one register per camera for blocks (1, 1), whose
// block bits are not looked at; a table of 8 entries for 2x2 blocks, the position moving on with the right
// beat); cornerness (`define F_KSEL): the k register that stage 2 multiplies holds the beat's camera's k.

// An undeclared name (e.g. a register MyHDL named otherwise) is an error, not an implicit 1-bit wire.
`default_nettype none
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
// Stereo: the stereo protocol (left then right beat of each pixel, both with the pixel's eol/eof, a token of
// either camera anywhere), the position moving on with the right beat; the table has an entry per block and
// camera, index 2 * block + cam.
reg f_ix = 1'b0, f_iy = 1'b0, f_iph = 1'b0;  // f_iph: the right camera's beat is due
wire f_ipix = sink_valid && (sink_eol || !sink_eof);
wire f_itok = sink_valid && sink_eof && !sink_eol;
always @(*) begin
    if (rst) assume(!sink_valid);
    if (f_ipix) begin
        assume(sink_eol == f_ix);
        assume(sink_eof == (sink_eol && f_iy));
`ifdef F_STEREO
        assume(sink_cam == f_iph);
`endif
    end
end
`ifdef F_STEREO
localparam F_NT = 8;  // table entries
wire [2:0] f_idx = {f_iy, f_ix, f_iph};  // = sink_cam on a pixel beat; a token: the camera due
wire f_istep = f_ipix && f_iph;  // the right beat ends the pixel
`else
localparam F_NT = 4;
wire [1:0] f_idx = {f_iy, f_ix};
wire f_istep = f_ipix;
`endif
always @(posedge clk)
    if (rst || f_itok) {f_iy, f_ix, f_iph} <= 3'd0;
    else if (f_ipix) begin
`ifdef F_STEREO
        f_iph <= !f_iph;
`endif
        if (f_istep) {f_iy, f_ix} <= {f_iy, f_ix} + 2'd1;
    end
// the table as written, entry i in bits [20 i +: 20] (not reset: the flags say what was written since rst)
reg [20*F_NT-1:0] f_tab = 0;
reg [F_NT-1:0] f_wr = 0;
integer f_k;
always @(posedge clk) begin
    if (thr_we) f_tab[20 * thr_addr +: 20] <= thr_data;
    if (rst) f_wr <= 0;
    else if (thr_we) f_wr[thr_addr] <= 1'b1;
end
// the table one clock late (read a clock ahead: a write counts from the second clock after it; after rst 0)
reg [20*F_NT-1:0] f_tab_d = 0;
reg [F_NT-1:0] f_wr_d = 0;
always @(posedge clk) begin
    f_tab_d <= f_tab;
    f_wr_d <= rst ? {F_NT{1'b0}} : f_wr;
end
always @(*) f_thr = f_wr_d[f_idx] ? f_tab_d[20 * f_idx +: 20] : 20'd0;
`ifdef F_STEREO
wire [2:0] f_idx_l = {f_iy, f_ix, 1'b0}, f_idx_r = {f_iy, f_ix, 1'b1};  // the block due, either camera
wire [19:0] f_thr_l = f_wr_d[f_idx_l] ? f_tab_d[20 * f_idx_l +: 20] : 20'd0;
wire [19:0] f_thr_r = f_wr_d[f_idx_r] ? f_tab_d[20 * f_idx_r +: 20] : 20'd0;
`endif
// invariants (they close the induction): the block position and the table agree with the reference
always @(*) if (f_past) begin
    assert(x == f_ix && y == f_iy && blk == {f_iy, f_ix});
    assert(block_position0_bx == f_ix && block_position0_by == f_iy && block_position0_base == {f_iy, 1'b0});
    // the last-column / -row flags (every block one pixel: always its last), the frame's last column / row
    assert(block_position0_xe && block_position0_ye);
    assert(block_position0_xw == f_ix && block_position0_yh == f_iy);
`ifdef F_STEREO
    // a table per camera (entry 2 * block + cam in the camera's memory); both cameras' thresholds of the
    // block due read a clock ahead into their registers; the camera due picks one
    assert(camera_tables0_written == f_wr);
    assert(camera_tables0_thr_l == f_thr_l && camera_tables0_thr_r == f_thr_r);
    assert((camera_tables0_due ? camera_tables0_thr_r : camera_tables0_thr_l) == f_thr);
    assert(camera_tables0_due == f_iph);
    for (f_k = 0; f_k < F_NT / 2; f_k = f_k + 1) begin
        assert(camera_tables0_mem_l[f_k] == f_tab[40 * f_k +: 20]);
        assert(camera_tables0_mem_r[f_k] == f_tab[40 * f_k + 20 +: 20]);
    end
`else
    assert(written == f_wr);
    assert(thr == f_thr);  // the threshold register: the beat due's, read a clock ahead
    for (f_k = 0; f_k < F_NT; f_k = f_k + 1) assert(mem[f_k] == f_tab[20 * f_k +: 20]);
`endif
end
`else
// one block (blocks (1, 1)): a register (per camera), 0 after rst
reg [19:0] f_glob = 20'd0;
`ifdef F_STEREO
reg [19:0] f_glob_r = 20'd0;   // the right camera's: written with thr_addr bit 0 high
always @(posedge clk)
    if (rst) {f_glob_r, f_glob} <= 40'd0;
    else if (thr_we && thr_addr[0]) f_glob_r <= thr_data;
    else if (thr_we) f_glob <= thr_data;
always @(*) f_thr = sink_cam ? f_glob_r : f_glob;
always @(*) if (f_past) assert(global_threshold0_stored == f_glob && global_threshold0_stored_r == f_glob_r);
`else
always @(posedge clk)
    if (rst) f_glob <= 20'd0;
    else if (thr_we) f_glob <= thr_data;
always @(*) f_thr = f_glob;
always @(*) if (f_past) assert(global_threshold0_stored == f_glob);  // invariant (closes the induction)
`endif
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
`ifdef F_STEREO
    cover(source_valid && source_cam && f_thr_p != 20'd0 && !f_pass);  // ... on the right camera
    cover(source_valid && !source_cam && f_thr_p != 20'd0 && !f_pass);  // ... on the left camera
`endif
`endif
`ifdef F_STEREO
    cover(source_valid && source_cam && source_eol && source_eof);  // a stereo frame's last (right) beat out
`endif
end

`ifdef F_KSEL
// ---- cornerness, stereo: the k of the beat's camera -------------------------------------------------------
// kq (registered with stage 1) is the k that stage 2 multiplies with the beat's trace: the left camera's k
// for a left beat, k_right for a right one (any beat: the register is not gated).
reg [7:0] f_kq = 8'd0, f_kl = 8'd0, f_kr = 8'd0;
reg f_kc = 1'b0, f_kv = 1'b0;
always @(posedge clk) begin
    f_kq <= sink_cam ? k_right : k;
    {f_kl, f_kr, f_kc, f_kv} <= {k, k_right, sink_cam, sink_valid};
end
// Shared multipliers (header `define F_KREG m2a, `define F_KWHEN p0): the operand register of the k
// product, loaded with the beat, holds it in the clock after the beat (p0), when it is multiplied.
`ifndef F_KREG
`define F_KREG kq
`define F_KWHEN 1'b1
`endif
always @(*) if (f_past && `F_KWHEN) assert(`F_KREG == f_kq);
always @(*) if (f_past) begin  // a right and a left beat, each taking its own k (the two k differ)
    cover(f_kv && f_kc && f_kl != f_kr && `F_KREG == f_kr);
    cover(f_kv && !f_kc && f_kl != f_kr && `F_KREG == f_kl);
end
`endif
