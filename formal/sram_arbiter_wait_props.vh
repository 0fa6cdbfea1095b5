// Bounded response of sram_arbiter's urgent masters (formal/run.py includes this file into MyHDL's Verilog of the block,
// just before endmodule). Run at width = height = 2, feature_words = 2, depth = 8, burst = 2, fetch_burst = 4,
// host_burst = 1, counter_bits = 16. One clock; rst is high in the first clock only.
//
// Environment. The masters' ports (cam0, cam1, fetch, rect, feat, host), the frame handshake (ctl), the
// status address and the read responses (rsp) are free inputs: any words, frames, tokens, requests,
// takes and releases on any clock. The controller keeps its documented contract (sram_bus.py, the
// fastest part: pipelined, read_latency 1): a read is always taken; a write is held off (cmd_ready low)
// only while a read taken in the last F_HOLD = read_latency + 1 = 2 clocks could still turn the bus
// round (tools/models/sram_controller.write_block_window).
//
// Masters (tools/models/sram_arbiter.MASTER_TABLE): 0 cam0, 1 cam1, 3 rect are urgent writers; 2 fetch,
// 4 feat, 5 host are not. startv[i]: master i asks for a turn; gv[i]: one of its accesses is issued.
// Same environment as sram_arbiter_props.vh (the controller's contract repeated here: one file per job).
localparam F_HOLD = 2;
localparam F_BU = 12;       // an urgent master waits at most this many clocks (docs/formal.md)

reg f_past = 1'b0;
always @(posedge clk) f_past <= 1'b1;

// ---- the controller's contract ---------------------------------------------------------------------
reg [F_HOLD - 1:0] f_rd_h = 0;   // bit j: a read was taken j + 1 clocks ago
always @(posedge clk) f_rd_h <= {f_rd_h[F_HOLD - 2:0], cmd_valid && cmd_ready && !cmd_we && !rst};
always @(*) begin
    assume(rst == !f_past);
    if (!cmd_ready) assume(cmd_we && f_rd_h != 0);
end

// ---- progress of each master: an access issued, or (a writer) a FIFO entry that leaves without one
//      (an abort, a dropped frame's word) ------------------------------------------------------------
wire [5:0] f_prog = gv | {1'b0, frame_writer3_pop, frame_writer2_pop, 1'b0, frame_writer1_pop, frame_writer0_pop};

// ---- (b) bounded response of the urgent masters -------------------------------------------------------
// f_wait[i]: clocks master i has asked (startv) without progress. An urgent master's wait is bounded
// whatever the other masters, the frame handshake and the controller (within its contract) do.
reg [4:0] f_w0 = 0, f_w1 = 0, f_w3 = 0;
always @(posedge clk) begin
    f_w0 <= (rst || !startv[0] || f_prog[0]) ? 5'd0 : (f_w0 == 5'd31 ? f_w0 : f_w0 + 5'd1);
    f_w1 <= (rst || !startv[1] || f_prog[1]) ? 5'd0 : (f_w1 == 5'd31 ? f_w1 : f_w1 + 5'd1);
    f_w3 <= (rst || !startv[3] || f_prog[3]) ? 5'd0 : (f_w3 == 5'd31 ? f_w3 : f_w3 + 5'd1);
end
always @(*) if (f_past && !rst) begin
    assert(f_w0 <= F_BU);
    assert(f_w1 <= F_BU);
    assert(f_w3 <= F_BU);
end

// ---- covers: a long wait is reachable (the bound itself is tight: F_BU = 11 fails at step 19 with a
//      12-clock wait of cam0; docs/formal.md) -----------------------------------------------------------
always @(*) if (f_past && !rst) begin
    cover(f_w0 == 5'd9);
    cover(f_w3 == 5'd9);
end
