// Formal properties of sram_controller (formal/run.py includes this file into MyHDL's Verilog of the block,
// just before endmodule). Run with kind=pipelined (SyncBurst: write data with the address, one idle bus
// cycle between the part's and the FPGA's drives) and read_latency=2 (the board's 100 MHz part). One clock.
// The rules are tools/sram.py's (the ones sim/lib/sram_model.py checks at every edge), written for the
// formal step s: the pins at step s are sampled by the part at the next edge and were stable during bus
// cycle s; a read in the pins at step s is driven by the part in cycle s + L (L = read_latency); a
// pipelined write in the pins at step s needs its data driven in cycle s (NoBL: s + L).
// The commands are free (valid, we, address, data, byte enables, tag on any clock), except that a write
// enables at least one byte. rst is high in the first clock only: a reset while a read is in flight leaves
// OE# high in the cycle the part would drive that read (so the part does not drive it: no contention, the
// read is lost as a reset should lose it), which tools/sram.py's model reports as an "output enable" break.
localparam F_L = 2;          // read latency
localparam F_WL = 0;         // write data latency: 0 pipelined, F_L NoBL
localparam F_TA = 1;         // turnaround cycles: 1 pipelined, 0 NoBL

reg f_past = 1'b0;
always @(posedge clk) f_past <= 1'b1;
always @(*) begin
    assume(rst == !f_past);
    if (cmd_valid && cmd_we) assume(cmd_be != 2'b00);
end

// ---- pin histories (bit i: i + 1 clocks ago) -----------------------------------------
wire f_rd = !sram_ce_n && sram_we_n;    // a read in the pins
wire f_wr = !sram_ce_n && !sram_we_n;   // a write in the pins
reg [3:0] f_rd_h = 4'd0, f_wr_h = 4'd0, f_oe_h = 4'd0;
reg [3:0] f_rfire_h = 4'd0, f_ok_h = 4'd0;
reg [4:0] f_tag_h [0:3];
reg [19:0] f_addr_p = 20'd0;
reg f_fire_p = 1'b0, f_wfire_p = 1'b0;
reg [1:0] f_be_p = 2'd0;
reg [15:0] f_wdata_p = 16'd0;
always @(posedge clk) begin
    f_rd_h <= {f_rd_h[2:0], f_rd};
    f_wr_h <= {f_wr_h[2:0], f_wr};
    f_oe_h <= {f_oe_h[2:0], sram_dq_oe};
    f_rfire_h <= {f_rfire_h[2:0], cmd_valid && !cmd_we && !rst};
    f_ok_h <= {f_ok_h[2:0], !rst};   // the history is valid (no rst) that many clocks back
    f_tag_h[0] <= cmd_tag; f_tag_h[1] <= f_tag_h[0]; f_tag_h[2] <= f_tag_h[1]; f_tag_h[3] <= f_tag_h[2];
    f_fire_p <= cmd_valid && cmd_ready && !rst;
    f_wfire_p <= cmd_valid && cmd_ready && cmd_we && !rst;
    f_addr_p <= cmd_addr;
    f_be_p <= cmd_be;
    f_wdata_p <= cmd_wdata;
end
// the part drives read data in this cycle: a read in the pins L clocks ago
wire f_part = f_rd_h[F_L - 1];
wire f_part_p = f_rd_h[F_L];
wire f_fpga = sram_dq_oe;
wire f_fpga_p = f_oe_h[0];
wire f_wdue = (F_WL == 0) ? f_wr : f_wr_h[F_WL - 1];   // a write samples DQ at the next edge

// ---- the part's rules ---------------------------------------------------------------------------------
reg [2:0] f_k = 3'd0;  // clocks since the first step (the histories are filled after 4)
always @(posedge clk) if (f_k != 3'd7) f_k <= f_k + 3'd1;
always @(*) if (f_past && f_k >= 3'd4) begin
    assert(sram_ld_n == 1'b0);                               // single accesses only
    if (f_wr) assert(sram_bw_n != 2'b11);                    // byte writes: at least one byte
    assert(!(f_fpga && f_part));                             // no bus contention
    if (f_part) assert(!sram_oe_n);                          // output enable while the part drives
    assert(f_fpga == f_wdue);                                // write data in the right cycle, no stray drive
    if (F_TA > 0) assert(!(f_fpga && f_part_p) && !(f_part && f_fpga_p));  // turnaround
end
// ---- the port: what the pins carry, the responses -------------------------------------------------------
always @(*) if (f_past && f_k >= 3'd4) begin
    // the pins carry the command taken in the clock before, and only that
    assert(!sram_ce_n == f_fire_p);
    assert(f_wr == f_wfire_p);
    if (f_fire_p) assert(sram_addr == f_addr_p);
    if (f_wfire_p) assert(sram_bw_n == ~f_be_p && sram_dq_o == f_wdata_p);
end
always @(*) if (f_past && f_k >= 3'd4 && f_ok_h[F_L + 1:0] == {(F_L + 2){1'b1}}) begin
    // one response per read, L + 2 clocks after it was taken, with its tag; the data is what the part
    // drove in the cycle its read's data was due
    assert(rsp_valid == f_rfire_h[F_L + 1]);
    if (rsp_valid) assert(rsp_tag == f_tag_h[F_L + 1] && f_part_p);
end

// ---- covers --------------------------------------------------------------------------------------
always @(*) if (f_past && f_k >= 3'd4) begin
    cover(f_part && f_oe_h[2]);                              // a read right after a write: its data 3 cycles after
    cover(f_fpga && f_part_p == 1'b0 && f_rd_h[F_L + 1]);    // a write as early as the turnaround allows
    cover(cmd_valid && cmd_we && !cmd_ready);                // a write held off
    cover(rsp_valid && f_rfire_h[0]);                        // reads back to back
end
