// Bounded wait of sram_arbiter's NON-urgent masters (fetch, feat, host) and their turn fairness (formal/run.py
// includes this file into MyHDL's Verilog of the block, just before endmodule). Run at width = height = 2,
// feature_words = 2, depth = 8, burst = 2, fetch_burst = 4, host_burst = 1, counter_bits = 16. One clock; rst
// is high in the first clock only.
//
// Environment: as sram_arbiter_wait_props.vh (the masters' ports, the frame handshake, the status address
// and the read responses free; the controller within its contract: a read always taken, a write held off
// only while a read taken in the last F_HOLD = 2 clocks could still turn the bus round), and, for the waiting
// bound, a RATE LIMIT on the urgent streams: each camera writer's FIFO receives at most one entry (a word or a
// reset token) in every F_NC clocks, the rectified writer's at most one in every F_NR clocks; with
// F_FRAME_ENDS, an urgent writer's entries with eof (frame ends, reset tokens) at least F_NE clocks apart.
// (In the system a camera delivers 9 M words/s during a line, one word per 11.1 memory clocks at 100 MHz, and
// its frames are 352 x 288 words; the rectifier gives one stereo pair, one word, per 8 clocks with both sides
// in range, per 2 clocks where both sides are black.) F_QUIET_CAM1 / F_QUIET_RECT silence those writers (no
// entry at all) for a reduced environment. F_FREE_URGENT drops the rate and the waiting bound (the fairness
// among the non-urgent masters needs neither). The job's header sets the defines; F_BN is the waiting bound,
// F_TN the fairness bound (docs/formal.md, sram_arbiter_fair and sram_arbiter_turns).
//
// Masters (tools/models/sram_arbiter.MASTER_TABLE): 0 cam0, 1 cam1, 3 rect urgent; 2 fetch, 4 feat, 5 host
// not. startv[i]: master i asks for a turn (fetch: a request in its issue stage; host: a request held; feat:
// a burst or a list's end in its FIFO); each keeps asking until it moves a word (its port protocol);
// gv[i]: one of its accesses is issued.
`ifndef F_NC
`define F_NC 11
`endif
`ifndef F_NR
`define F_NR 8
`endif
`ifndef F_BN
`define F_BN 18
`endif
`ifndef F_NE
`define F_NE 44
`endif
`ifndef F_TN
`define F_TN 2
`endif
localparam F_HOLD = 2;
localparam F_NC = `F_NC, F_NR = `F_NR, F_BN = `F_BN, F_TN = `F_TN, F_NE = `F_NE;

reg f_past = 1'b0;
always @(posedge clk) f_past <= 1'b1;

// ---- the controller's contract (as sram_arbiter_wait_props.vh) ----------------------------------------
reg [F_HOLD - 1:0] f_rd_h = 0;   // bit j: a read was taken j + 1 clocks ago
always @(posedge clk) f_rd_h <= {f_rd_h[F_HOLD - 2:0], cmd_valid && cmd_ready && !cmd_we && !rst};
always @(*) begin
    assume(rst == !f_past);
    if (!cmd_ready) assume(cmd_we && f_rd_h != 0);
end

// ---- the urgent streams' rate: f_gK = clocks since writer K's last FIFO entry (saturating) -------------
// (writers: frame_writer0 cam0, frame_writer1 cam1, frame_writer2 rect, frame_writer3 feat)
reg [5:0] f_g0 = 6'd63, f_g1 = 6'd63, f_g2 = 6'd63;
always @(posedge clk) begin
    f_g0 <= frame_writer0_push ? 6'd1 : (f_g0 == 6'd63 ? f_g0 : f_g0 + 6'd1);
    f_g1 <= frame_writer1_push ? 6'd1 : (f_g1 == 6'd63 ? f_g1 : f_g1 + 6'd1);
    f_g2 <= frame_writer2_push ? 6'd1 : (f_g2 == 6'd63 ? f_g2 : f_g2 + 6'd1);
end
reg [7:0] f_e0 = 8'd255, f_e1 = 8'd255, f_e2 = 8'd255;   // clocks since writer K's last eof entry
always @(posedge clk) begin
    f_e0 <= frame_writer0_push_eof ? 8'd1 : (f_e0 == 8'd255 ? f_e0 : f_e0 + 8'd1);
    f_e1 <= frame_writer1_push_eof ? 8'd1 : (f_e1 == 8'd255 ? f_e1 : f_e1 + 8'd1);
    f_e2 <= frame_writer2_push_eof ? 8'd1 : (f_e2 == 8'd255 ? f_e2 : f_e2 + 8'd1);
end
`ifndef F_FREE_URGENT
always @(*) begin
    if (frame_writer0_push) assume(f_g0 >= F_NC);
    if (frame_writer1_push) assume(f_g1 >= F_NC);
    if (frame_writer2_push) assume(f_g2 >= F_NR);
`ifdef F_FRAME_ENDS
    // frame ends (a frame's last word or a reset token: an entry with eof) at least F_NE clocks apart
    if (frame_writer0_push_eof) assume(f_e0 >= F_NE);
    if (frame_writer1_push_eof) assume(f_e1 >= F_NE);
    if (frame_writer2_push_eof) assume(f_e2 >= F_NE);
`endif
`ifdef F_QUIET_CAM1
    assume(!frame_writer1_push);
`endif
`ifdef F_QUIET_RECT
    assume(!frame_writer2_push);
`endif
end
`endif

// ---- progress: an access issued, or (feat) a FIFO entry that leaves without one -------------------------
wire [5:0] f_prog = gv | {1'b0, frame_writer3_pop, frame_writer2_pop, 1'b0, frame_writer1_pop, frame_writer0_pop};

// ---- bounded wait of the non-urgent masters ------------------------------------------------------------
// f_wI: clocks master I has asked (startv) without progress.
reg [6:0] f_w2 = 0, f_w4 = 0, f_w5 = 0;
always @(posedge clk) begin
    f_w2 <= (rst || !startv[2] || f_prog[2]) ? 7'd0 : (f_w2 == 7'd127 ? f_w2 : f_w2 + 7'd1);
    f_w4 <= (rst || !startv[4] || f_prog[4]) ? 7'd0 : (f_w4 == 7'd127 ? f_w4 : f_w4 + 7'd1);
    f_w5 <= (rst || !startv[5] || f_prog[5]) ? 7'd0 : (f_w5 == 7'd127 ? f_w5 : f_w5 + 7'd1);
end
`ifndef F_FREE_URGENT
always @(*) if (f_past && !rst) begin
    assert(f_w2 <= F_BN);
    assert(f_w4 <= F_BN);
    assert(f_w5 <= F_BN);
end
`endif

// ---- turn fairness among the non-urgent masters --------------------------------------------------------
// Round robin as the arbiter does it: the next owner is chosen a clock ahead (nxt), from the masters asking
// in that clock. f_tIJ counts the turns of J *chosen while I asks* (I asked in the clock of the choice and
// still asks when the turn starts) that move a word (their first access), from I's first ask or its last turn
// start. It stays within F_TN = 2, whatever the urgent masters do (no rate needed): no master is served three
// times while another waits for its turn. Not 1: after a one-clock turn (host's, host_burst 1) the next owner
// was chosen before that turn began, from the round robin's old place, so the order can run past host again
// (fetch waits while host is served twice: host, feat chosen from the old place, host; docs/formal.md).
// Not counted: a turn chosen before I asked (it may already be under way), and turns that move no word (the
// same stale choice gives host an empty second turn; feat is given turns while its frame's first word still
// waits for its buffer).
wire f_ts = turn_over && nxt_v && !nxt_urg;        // a non-urgent turn of master nxt starts at this edge
wire f_ts2 = f_ts && nxt == 3'd2, f_ts4 = f_ts && nxt == 3'd4, f_ts5 = f_ts && nxt == 3'd5;
reg f_sp2 = 1'b0, f_sp4 = 1'b0, f_sp5 = 1'b0;      // startv[I] in the clock before (when nxt was chosen)
reg f_c2 = 1'b0, f_c4 = 1'b0, f_c5 = 1'b0;         // the current turn was chosen while I asked
always @(posedge clk) begin
    f_sp2 <= startv[2] && !rst;
    f_sp4 <= startv[4] && !rst;
    f_sp5 <= startv[5] && !rst;
    if (turn_over) begin
        f_c2 <= f_sp2 && startv[2];
        f_c4 <= f_sp4 && startv[4];
        f_c5 <= f_sp5 && startv[5];
    end
end
wire f_f2 = gv[2] && !served, f_f4 = gv[4] && !served, f_f5 = gv[5] && !served;   // a turn's first word
reg [1:0] f_t24 = 0, f_t25 = 0, f_t42 = 0, f_t45 = 0, f_t52 = 0, f_t54 = 0;
always @(posedge clk) begin
    f_t24 <= (rst || !startv[2] || f_ts2) ? 2'd0 : (f_f4 && f_c2 && f_t24 != 2'd3 ? f_t24 + 2'd1 : f_t24);
    f_t25 <= (rst || !startv[2] || f_ts2) ? 2'd0 : (f_f5 && f_c2 && f_t25 != 2'd3 ? f_t25 + 2'd1 : f_t25);
    f_t42 <= (rst || !startv[4] || f_ts4) ? 2'd0 : (f_f2 && f_c4 && f_t42 != 2'd3 ? f_t42 + 2'd1 : f_t42);
    f_t45 <= (rst || !startv[4] || f_ts4) ? 2'd0 : (f_f5 && f_c4 && f_t45 != 2'd3 ? f_t45 + 2'd1 : f_t45);
    f_t52 <= (rst || !startv[5] || f_ts5) ? 2'd0 : (f_f2 && f_c5 && f_t52 != 2'd3 ? f_t52 + 2'd1 : f_t52);
    f_t54 <= (rst || !startv[5] || f_ts5) ? 2'd0 : (f_f4 && f_c5 && f_t54 != 2'd3 ? f_t54 + 2'd1 : f_t54);
end
always @(*) if (f_past && !rst) begin
    assert(f_t24 <= F_TN && f_t25 <= F_TN);
    assert(f_t42 <= F_TN && f_t45 <= F_TN);
    assert(f_t52 <= F_TN && f_t54 <= F_TN);
end

// ---- covers: long waits of each non-urgent master are reachable -----------------------------------------
always @(*) if (f_past && !rst) begin
    cover(f_w2 == 7'd10);
    cover(f_w4 == 7'd10);
    cover(f_w5 == 7'd10);
    cover(f_t24 == 2'd1 && f_t25 == 2'd1);   // fetch waits while feat and host each have a turn
end
