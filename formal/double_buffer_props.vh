// Formal properties of double_buffer (formal/run.py includes this file into MyHDL's Verilog of the block,
// just before endmodule). One clock. The producer side keeps writer_issue's protocol (assumed): it asks
// (p_start) only while it holds no buffer, and it completes (p_done) or abandons (p_abort) only the buffer
// it was granted, once, after the grant. The consumer (c_take, c_release) is free: any pattern of takes
// and releases. rst is high in the first clock only.
localparam [1:0] F_FREE = 2'd0, F_WRITING = 2'd1, F_FULL = 2'd2, F_READING = 2'd3;

reg f_past = 1'b0;
always @(posedge clk) f_past <= 1'b1;

// ---- the producer's protocol (a shadow of what it holds) ------------------------------------------
reg f_wr_v = 1'b0;      // the producer holds a buffer (granted, not yet done or aborted)
reg f_wr_buf = 1'b0;    // which one
always @(posedge clk) begin
    if (rst) f_wr_v <= 1'b0;
    else if (side_p_grant) begin f_wr_v <= 1'b1; f_wr_buf <= side_p_gbuf; end
    else if (side_p_done || side_p_abort) f_wr_v <= 1'b0;
end
always @(*) begin
    assume(rst == !f_past);
    if (side_p_start) assume(!f_wr_v);
    if (side_p_done) assume(f_wr_v && side_p_done_buf == f_wr_buf && !side_p_abort);
    if (side_p_abort) assume(f_wr_v && side_p_abort_buf == f_wr_buf);
end

// ---- a shadow of the publications: the buffer published last ----------------------------------------
reg f_last = 1'b0;      // the buffer of the latest p_done
always @(posedge clk) if (!rst && side_p_done) f_last <= side_p_done_buf;

wire [1:0] f_st0 = side_state[1:0];
wire [1:0] f_st1 = side_state[3:2];
wire f_full0 = f_st0 == F_FULL, f_full1 = f_st1 == F_FULL;
wire f_taking = side_c_take && side_c_avail;   // (c_avail is low while a buffer is held)

// the take of the previous clock, and what the buffers were then
reg f_took = 1'b0, f_full0_p = 1'b0, f_full1_p = 1'b0, f_last_p = 1'b0;
always @(posedge clk) begin
    f_took <= !rst && f_taking;
    f_full0_p <= f_full0;
    f_full1_p <= f_full1;
    f_last_p <= f_last;
end

always @(*) if (f_past && !rst) begin
    // the buffer the producer writes is WRITING, and no other one is (also in the clock of the grant,
    // when the state has changed and the producer learns it from p_grant)
    assert((f_st0 == F_WRITING) == ((f_wr_v && !f_wr_buf) || (side_p_grant && !side_p_gbuf)));
    assert((f_st1 == F_WRITING) == ((f_wr_v && f_wr_buf) || (side_p_grant && side_p_gbuf)));
    assert(!(f_wr_v && side_p_grant));
    // the consumer holds exactly the READING buffer: never one that is WRITING (nor FREE / FULL)
    assert((f_st0 == F_READING) == (side_c_held && !side_c_buf));
    assert((f_st1 == F_READING) == (side_c_held && side_c_buf));
    if (side_c_held) assert((side_c_buf ? f_st1 : f_st0) != F_WRITING);
    // a buffer can be taken exactly when one is FULL and none is held
    assert(side_c_avail == ((f_full0 || f_full1) && !side_c_held));
    // under this protocol a start always finds a buffer (the producer holds none when it asks, the
    // consumer at most one): no frame is ever dropped
    assert(!side_p_deny);
    // published frames: both FULL only after both were published, the newest one is f_last
    if (f_full0 && f_full1) assert(newest == f_last);
end

// the take: the consumer gets the newest FULL buffer (the one published last if both are FULL)
always @(*) if (f_past && !rst && f_took) begin
    assert(side_c_held);
    assert(side_c_buf ? f_full1_p : f_full0_p);
    if (f_full0_p && f_full1_p) assert(side_c_buf == f_last_p);
    // and the older FULL one is gone (FREE, or WRITING if the producer started on it): never taken after it
    if (f_full0_p && f_full1_p) assert((side_c_buf ? f_st0 : f_st1) != F_FULL);
end

// the producer's pick: never the buffer the consumer holds or takes; a FREE one before a FULL one; of two
// FULL ones the older
wire [1:0] f_other_st = side_p_pick ? f_st0 : f_st1;
always @(*) if (f_past && !rst && side_p_avail) begin
    assert((side_p_pick ? f_st1 : f_st0) == F_FREE || (side_p_pick ? f_st1 : f_st0) == F_FULL);
    if (f_taking) assert(side_p_pick != (f_full0 && f_full1 ? f_last : f_full1));
    if ((side_p_pick ? f_st1 : f_st0) == F_FULL && !f_taking) begin
        assert(f_other_st != F_FREE);
        if (f_other_st == F_FULL) assert(side_p_pick != f_last);
    end
end

// ---- covers -----------------------------------------------------------------------------------
reg f_handed = 1'b0;    // a frame was published and taken
always @(posedge clk) if (!rst && f_taking) f_handed <= 1'b1;
always @(*) if (f_past && !rst) begin
    cover(f_took && f_full0_p && f_full1_p);              // a take with two FULL buffers: the newest one
    cover(f_handed && side_p_grant && f_wr_v == 1'b0 && side_c_held);  // the producer writes while the consumer reads
    cover(side_overwritten != 16'd0 && side_c_held);       // an older FULL frame overwritten while one is read
    cover(side_c_held && side_c_buf && f_full0);           // buffer 1 read, buffer 0 FULL waiting
end
