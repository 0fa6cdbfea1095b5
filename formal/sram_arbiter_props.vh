// Formal properties of sram_arbiter (formal/run.py includes this file into MyHDL's Verilog of the block,
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
// 4 feat, 5 host are not. gv[i]: one of master i's accesses is issued. The waiting bound is in
// sram_arbiter_wait_props.vh (a bounded check).
localparam F_HOLD = 2;

reg f_past = 1'b0;
always @(posedge clk) f_past <= 1'b1;

// ---- the controller's contract ---------------------------------------------------------------------
reg [F_HOLD - 1:0] f_rd_h = 0;   // bit j: a read was taken j + 1 clocks ago
always @(posedge clk) f_rd_h <= {f_rd_h[F_HOLD - 2:0], cmd_valid && cmd_ready && !cmd_we && !rst};
always @(*) begin
    assume(rst == !f_past);
    if (!cmd_ready) assume(cmd_we && f_rd_h != 0);
end

// ---- (a) one owner; every command is the owner's ----------------------------------------------------
reg [41:0] f_acc = 0;      // the owner's access in the clock of an issue
reg f_issued = 1'b0;
always @(posedge clk) begin
    f_issued <= issue && !rst;
    case (own)
        3'd0: f_acc <= a0;
        3'd1: f_acc <= a1;
        3'd2: f_acc <= a2;
        3'd3: f_acc <= a3;
        3'd4: f_acc <= a4;
        default: f_acc <= a5;
    endcase
end
// the command of the previous clock, and whether the controller took it
reg f_cmd_wait = 1'b0;
reg [41:0] f_cmd_p = 0;
wire [41:0] f_cmd = {cmd_tag, cmd_be, cmd_we, cmd_wdata, cmd_addr};   // the ACCESS packing (tag on top)
always @(posedge clk) begin
    f_cmd_wait <= cmd_valid && !cmd_ready && !rst;
    f_cmd_p <= f_cmd;
end

always @(*) if (f_past && !rst) begin
    // at most one master granted, and only the owner, while it owns the bus
    assert((gv & (gv - 6'd1)) == 6'd0);
    assert(own <= 3'd5 && nxt <= 3'd5 && last1 <= 3'd5);
    if (gv != 0) assert(own_v && gv == (6'd1 << own) && issue);
    assert(issue == (gv != 0));
    // a command is offered exactly after an issue, or while the controller holds it off; it is the
    // owner's access of the issuing clock, held unchanged until taken
    assert(cmd_valid == (f_issued || f_cmd_wait));
    if (f_issued) assert(f_cmd == f_acc);
    if (f_cmd_wait) assert(!f_issued && f_cmd == f_cmd_p);
    // a turn is owned by one master: the owner's turn length is within its burst
    if (own_v) assert(beats <= ((own == 3'd2) ? 3'd4 : (own == 3'd5) ? 3'd1 : 3'd2));
    // the owner and the next owner are kept twice, binary and one-hot (the grant reads the one-hot copy)
    assert(own1h == (own_v ? (6'd1 << own) : 6'd0));
    assert(nxt1h == (nxt_v ? (6'd1 << nxt) : 6'd0));
    // each writer's registered req (worked out a clock ahead for both answers of the arbiter) is its rule on
    // the head entry: a word, not an abort, not of a dropped frame, its frame's buffer claimed (or not its first)
    assert(frame_writer0_writer_issue0_head_req == (frame_writer0_writer_issue0_has && !frame_writer0_writer_issue0_abt
        && !frame_writer0_writer_issue0_discard && (frame_writer0_writer_issue0_claimed || !frame_writer0_writer_issue0_sof)));
    assert(frame_writer1_writer_issue1_head_req == (frame_writer1_writer_issue1_has && !frame_writer1_writer_issue1_abt
        && !frame_writer1_writer_issue1_discard && (frame_writer1_writer_issue1_claimed || !frame_writer1_writer_issue1_sof)));
    assert(frame_writer2_writer_issue2_head_req == (frame_writer2_writer_issue2_has && !frame_writer2_writer_issue2_abt
        && !frame_writer2_writer_issue2_discard && (frame_writer2_writer_issue2_claimed || !frame_writer2_writer_issue2_sof)));
    assert(frame_writer3_writer_issue3_head_req == (frame_writer3_writer_issue3_has && !frame_writer3_writer_issue3_abt
        && !frame_writer3_writer_issue3_discard && (frame_writer3_writer_issue3_claimed || !frame_writer3_writer_issue3_sof)));
end

// ---- covers ------------------------------------------------------------------------------------------
always @(*) if (f_past && !rst) begin
    cover(gv[0]);
    cover(gv[1]);
    cover(gv[2]);
    cover(gv[3]);
    cover(gv[4]);
    cover(gv[5]);
end
