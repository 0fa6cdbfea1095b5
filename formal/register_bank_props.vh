// Formal properties of register_bank's AXI4-Lite slave (formal/run.py includes this file into MyHDL's Verilog
// of the block, just before endmodule). Run with width=4, height=3 (only the GEOMETRY word depends on them);
// the register map is tools/regmap.py's REGMAP (23 address bits). One clock.
// Assumed: rst in the first clock; an AXI4-Lite master (a valid stays high with its payload unchanged until
// its transfer; no valid during reset); bready, rready, every status input, the window ports' data and the
// arbiter's host port free (any value on any clock).
// Asserted (the slave's side of the AXI rules and of docs/registers.md's bus behaviour):
//   * awready and wready together, and only with awvalid and wvalid (a write's address and data move at
//     the same edge); arready only with arvalid; one access at a time (no request moves while a response
//     is owed);
//   * bvalid / rvalid stay high until bready / rready, bresp / rdata / rresp unchanged while they wait;
//   * exactly one response per request: a response only for a request that moved and whose response
//     has not moved yet; every local access answered within 3 clocks (write) / 5 clocks (read) of its
//     transfer; an SRAM access asks the host port within 2 clocks and is answered the clock after the host
//     port takes the write / returns the read data (with that data);
//   * the response: OKAY for a mapped access, SLVERR for an address where nothing is mapped and for a write
//     to a const, status or window register (a reference decoder of the map below, written from
//     docs/registers.md), read data 0 with SLVERR; a write answered SLVERR changes no output.

reg f_past = 1'b0;
always @(posedge clk) f_past <= 1'b1;
always @(*) if (!f_past) assume(rst);

// ---- the master (assumed) -----------------------------------------------------------------------------
always @(*) if (rst) assume(!bus_awvalid && !bus_wvalid && !bus_arvalid);
always @(posedge clk) if (f_past && !$past(rst)) begin
    if ($past(bus_awvalid && !bus_awready)) assume(bus_awvalid && $stable(bus_awaddr));
    if ($past(bus_wvalid && !bus_wready)) assume(bus_wvalid && $stable(bus_wdata) && $stable(bus_wstrb));
    if ($past(bus_arvalid && !bus_arready)) assume(bus_arvalid && $stable(bus_araddr));
end

// ---- the reference decoder (word address: the byte address without its two low bits) --------------------
function f_sram(input [20:0] w);  // SRAM: byte addresses 0x400000..
    f_sram = w[20];
endfunction
function f_readable(input [20:0] w);  // a mapped local word: ID .. K_RIGHT, FRAMES .. FRAME_CLOCKS, THR_*, FCOUNT, ARB
    f_readable = w[20:8] == 0 && (w[7:0] <= 8'h06 || (w[7:0] >= 8'h08 && w[7:0] <= 8'h0C)
                                  || (w[7:0] >= 8'h40 && w[7:0] <= 8'h95));
endfunction
function f_writable(input [20:0] w);  // CTRL, CMD, K_LEFT, K_RIGHT, THR_LEFT, THR_RIGHT
    f_writable = w[20:8] == 0 && (w[7:0] == 8'h02 || w[7:0] == 8'h03 || w[7:0] == 8'h05 || w[7:0] == 8'h06
                                  || (w[7:0] >= 8'h40 && w[7:0] <= 8'h5F));
endfunction

// ---- the requests and responses that moved -------------------------------------------------------------
wire f_aw = bus_awvalid && bus_awready, f_w = bus_wvalid && bus_wready, f_ar = bus_arvalid && bus_arready;
wire f_b = bus_bvalid && bus_bready, f_r = bus_rvalid && bus_rready;
reg f_wout = 1'b0, f_rout = 1'b0;  // a write / read moved, its response has not
reg [20:0] f_addr = 21'd0;         // its word address
reg [3:0] f_strb = 4'd0;           // its byte strobes (write)
reg [2:0] f_age = 3'd0;            // clocks since it moved (saturating)
reg f_hmoved = 1'b0;               // its host request moved (SRAM accesses)
wire f_hreq = host_req_valid && host_req_ready;
always @(posedge clk)
    if (rst) begin
        f_wout <= 1'b0;
        f_rout <= 1'b0;
    end else begin
        if (f_aw) begin
            f_wout <= 1'b1;
            f_addr <= bus_awaddr[22:2];
            f_strb <= bus_wstrb;
            f_age <= 3'd0;
            f_hmoved <= 1'b0;
        end
        if (f_ar) begin
            f_rout <= 1'b1;
            f_addr <= bus_araddr[22:2];
            f_age <= 3'd0;
            f_hmoved <= 1'b0;
        end
        if (f_b) f_wout <= 1'b0;
        if (f_r) f_rout <= 1'b0;
        if (!f_aw && !f_ar && f_age != 3'd7) f_age <= f_age + 3'd1;
        if (f_hreq) f_hmoved <= 1'b1;
    end
wire f_ok_w = f_sram(f_addr) || f_writable(f_addr);
wire f_ok_r = f_sram(f_addr) || f_readable(f_addr);

always @(*) if (f_past && !rst) begin
    // handshakes
    assert(bus_awready == bus_wready);
    if (bus_awready) assert(bus_awvalid && bus_wvalid && !f_wout && !f_rout);
    if (bus_arready) assert(bus_arvalid && !f_wout && !f_rout);
    assert(!(bus_awready && bus_arready));
    // no response without a request, none twice
    if (bus_bvalid) assert(f_wout);
    if (bus_rvalid) assert(f_rout);
    assert(!(f_wout && f_rout));
    // the response's code; read data 0 with SLVERR
    if (bus_bvalid) assert(bus_bresp == (f_ok_w ? 2'd0 : 2'd2));
    if (bus_rvalid) assert(bus_rresp == (f_ok_r ? 2'd0 : 2'd2));
    if (bus_rvalid && !f_ok_r) assert(bus_rdata == 32'd0);
    // every local access answered in time: a write 3 clocks, a read 5 clocks after it moved
    if (f_wout && !f_sram(f_addr) && !bus_bvalid) assert(f_age < 3'd2);
    if (f_rout && !f_sram(f_addr) && !bus_rvalid) assert(f_age < 3'd4);
    // an SRAM access: its host request within 2 clocks (a write with wstrb[1:0] = 0 is answered instead),
    // the request the access's (read or write, address, data, byte enables), held until taken
    if ((f_wout || f_rout) && f_sram(f_addr) && !f_hmoved && f_age >= 3'd2)
        assert(host_req_valid || (f_wout && f_strb[1:0] == 2'b00 && bus_bvalid));
    if (host_req_valid) begin
        assert((f_wout || f_rout) && f_sram(f_addr) && !f_hmoved);
        assert(host_req_we == f_wout && host_req_addr == f_addr[19:0]);
        if (f_wout) assert(host_req_be == f_strb[1:0] && host_req_be != 2'b00);
    end
    if (f_hmoved) assert(!host_req_valid);
end
always @(posedge clk) if (f_past && !$past(rst) && !rst) begin
    // a valid response waits for its ready with its payload unchanged
    if ($past(bus_bvalid && !bus_bready)) assert(bus_bvalid && $stable(bus_bresp));
    if ($past(bus_rvalid && !bus_rready)) assert(bus_rvalid && $stable(bus_rresp) && $stable(bus_rdata));
    if ($past(host_req_valid && !host_req_ready)) assert(host_req_valid);
    // the SRAM answers one clock after the host port does: a write when its request is taken, a read when
    // its data returns (with that data)
    if ($past(f_wout && f_hreq)) assert(bus_bvalid && bus_bresp == 2'd0);
    if ($past(f_rout && f_hmoved && host_rsp_valid && !bus_rvalid))
        assert(bus_rvalid && bus_rresp == 2'd0 && bus_rdata == $past(host_rsp_data));
    // a write answered SLVERR changes no output (CTRL, K_LEFT, CMD's pulses, THR_LEFT's write port)
    if (!$stable(regs_mode) || !$stable(regs_k_left) || regs_start || regs_thr_left_we)
        assert(f_wout && f_ok_w);
    if (!$stable(regs_k_left)) assert(f_addr == 21'h5);
    if (regs_thr_left_we) assert(f_addr[20:4] == 17'h4);
end

// ---- invariants (the bank's state machine against the access in flight: they make the induction close) ---
// state: 0 IDLE, 1 AR, 2 AW, 3 RD, 4 WR, 5 SRAM_RQ, 6 SRAM_RSP, 7 B, 8 R (MyHDL's enum encoding)
always @(*) if (f_past && !rst) begin
    assert(state <= 4'd8);
    assert(awready == (state == 4'd2) && wready == awready && arready == (state == 4'd1));
    assert(bvalid == (state == 4'd7) && rvalid == (state == 4'd8) && req_valid == (state == 4'd5));
    if (state <= 4'd2) assert(!f_wout && !f_rout);
    if (state == 4'd4 || state == 4'd7) assert(f_wout);
    if (state == 4'd3 || state == 4'd6 || state == 4'd8) assert(f_rout);
    if (state == 4'd5) assert(req_we ? f_wout : f_rout);
    if (state == 4'd6) assert(!req_we);
    if (state >= 4'd3) assert(waddr == f_addr);
    if (f_wout && state >= 4'd4) assert(wstrb == f_strb);
    if (state == 4'd3 || state == 4'd4) assert(f_age == {1'b0, cnt} && (!mem_sel || cnt == 2'd0));
    if (state == 4'd4) assert(cnt <= 2'd1);
    if (state == 4'd5) assert(f_sram(f_addr) && !f_hmoved && (!f_wout || f_strb[1:0] != 2'b00));
    if (state == 4'd6 || (state == 4'd8 && f_sram(f_addr))) assert(f_hmoved);
    if (state == 4'd7 && f_sram(f_addr) && f_strb[1:0] != 2'b00) assert(f_hmoved);
end

// ---- covers --------------------------------------------------------------------------------------
reg f_bwait = 1'b0;  // bvalid was high without bready in the clock before
always @(posedge clk) f_bwait <= bus_bvalid && !bus_bready;
always @(*) if (f_past && !rst) begin
    cover(bus_bvalid && bus_bready && f_addr == 21'h0 && bus_bresp == 2'd2);   // a write to ID (const): SLVERR
    cover(bus_rvalid && bus_rready && f_addr == 21'h7 && bus_rresp == 2'd2);   // a read of 0x1C (unmapped): SLVERR
    cover(bus_bvalid && bus_bready && f_addr == 21'h5 && bus_bresp == 2'd0 && regs_k_left == 8'hA5);  // K_LEFT written
    cover(bus_rvalid && bus_rready && f_addr == 21'h5 && bus_rdata == 32'hA5);  // ... and read back
    cover(bus_rvalid && bus_rready && f_sram(f_addr) && bus_rdata == 32'h1234); // an SRAM read through the host port
    cover(f_bwait && bus_bvalid && bus_bready);                               // a response held for bready
end
