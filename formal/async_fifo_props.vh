// Formal properties of async_fifo (formal/run.py includes this file into MyHDL's Verilog of the block,
// just before endmodule). Run with depth=4 (3-bit pointers: 2 address bits + a wrap bit), data_width=2.
// Model: multiclock on. wclk and rclk are free inputs (any edge pattern, any frequency ratio,
// simultaneous edges too); one solver step = one tick of the global clock. Both resets are free inputs.

reg f_past = 1'b0;
always @($global_clock) f_past <= 1'b1;

// ---- previous-step copies ($past is allowed in clocked blocks only) -----------------------------
reg f_wclk_p = 1'b0, f_rclk_p = 1'b0;
reg [2:0] f_wgray_p = 3'd0, f_rgray_p = 3'd0;
reg [4:0] f_sink_p = 5'd0;  // wrst, valid, eol, eof, data[1:0] without data: see below
reg [1:0] f_sdata_p = 2'd0;
reg [1:0] f_rin_p = 2'd0;   // rrst, source_ready
always @($global_clock) begin
    f_wclk_p <= wclk;
    f_rclk_p <= rclk;
    f_wgray_p <= wgray;
    f_rgray_p <= rgray;
    f_sink_p <= {1'b0, wrst, sink_valid, sink_eol, sink_eof};
    f_sdata_p <= sink_data;
    f_rin_p <= {rrst, source_ready};
end
wire f_wrose = f_past && wclk && !f_wclk_p;
wire f_rrose = f_past && rclk && !f_rclk_p;

// Inputs are synchronous to their clock: they change only together with its rising edge.
always @($global_clock) if (f_past) begin
    if (!f_wrose) assume({1'b0, wrst, sink_valid, sink_eol, sink_eof} == f_sink_p && sink_data == f_sdata_p);
    if (!f_rrose) assume({rrst, source_ready} == f_rin_p);
end

function [2:0] g2b(input [2:0] g);
    g2b = {g[2], g[2] ^ g[1], g[2] ^ g[1] ^ g[0]};
endfunction

wire [2:0] f_occ = wbin - rbin;                  // words in the memory (true occupancy)
wire [2:0] f_rs1 = g2b(rgray_s1), f_rs2 = g2b(rgray_s2);  // the read pointer as the write side sees it
wire [2:0] f_ws1 = g2b(wgray_s1), f_ws2 = g2b(wgray_s2);  // the write pointer as the read side sees it
// the pointer chains, in pointer order, summed without wrapping:
//   write side: rgray_s2 <= rgray_s1 <= rgray <= wgray;  read side: rgray <= wgray_s2 <= wgray_s1 <= wgray
wire [2:0] f_d_rs21 = f_rs1 - f_rs2, f_d_rs1r = rbin - f_rs1, f_d_ws21 = f_ws1 - f_ws2, f_d_ws1w = wbin - f_ws1;
wire [2:0] f_d_rws2 = f_ws2 - rbin, f_d_rs2w = wbin - f_rs2;
wire [4:0] f_wchain = f_d_rs21 + f_d_rs1r + f_occ;
wire [4:0] f_rchain = f_d_rws2 + f_d_ws21 + f_d_ws1w;

// ---- the tagged word: one write chosen by the solver, followed to the read port ----------------
wire f_pick = $anyseq;
reg f_tag = 1'b0, f_tag_rd = 1'b0, f_tag_out = 1'b0;
reg [2:0] f_tptr = 3'd0;
reg [3:0] f_tdata = 4'd0;
always @(posedge wclk) if (we && f_pick && !f_tag) begin
    f_tag <= 1'b1;
    f_tptr <= wbin;
    f_tdata <= wword;
end
always @(posedge rclk) begin
    if (load && f_tag && !f_tag_rd && rbin == f_tptr) f_tag_rd <= 1'b1;
    if (f_tag_rd && !f_tag_out && (take || drop_q || rrst)) f_tag_out <= 1'b1;
end
reg f_tag_taken = 1'b0;  // for the cover: the tagged word left through the port
always @(posedge rclk) if (f_tag_rd && !f_tag_out && take) f_tag_taken <= 1'b1;

// ---- the properties -----------------------------------------------------------------------------
always @(*) begin
    // Gray pointers are the Gray code of the binary ones
    assert(wgray == (wbin ^ (wbin >> 1)));
    assert(rgray == (rbin ^ (rbin >> 1)));
    // never more than depth words; the synchronised views lag, never lead
    assert(f_occ <= 3'd4);
    assert(f_wchain == f_d_rs2w && f_d_rs2w <= 3'd4);
    assert(f_rchain == f_occ);
    // the flags are right: full/empty are the binary comparisons with the synchronised pointer
    // (the Gray mask trick), and conservative: really full => full, really empty => empty
    assert(full_s == (wbin - f_rs2 == 3'd4));
    assert(empty_s == (rbin == f_ws2));
    if (f_occ == 3'd4) assert(full_s);
    if (f_occ == 3'd0) assert(empty_s);
    // no word lost (no write into an unread entry), no word duplicated (no read of an entry not written)
    if (we) assert(f_occ < 3'd4);
    if (load) assert(f_occ != 3'd0);
    // the tagged word waits unaltered in the memory, in its place in the order, until it is read ...
    if (f_tag && !f_tag_rd) begin
        assert(mem[f_tptr[1:0]] == f_tdata);
        assert(f_tptr - rbin < f_occ);
    end
    // ... then sits in the output register, offered with the port's fields, until taken (or rrst)
    if (f_tag_rd && !f_tag_out) begin
        assert(q_full && q == f_tdata && rbin == f_tptr + 3'd1);
        if (source_valid) assert({source_eof, source_eol, source_data} == f_tdata);
    end
    if (!f_tag) assert(!f_tag_rd);
    if (!f_tag_rd) assert(!f_tag_out);
end

// the pointers that cross change one bit at a time (per step of the global clock)
always @($global_clock) if (f_past) begin
    assert($onehot0(wgray ^ f_wgray_p));
    assert($onehot0(rgray ^ f_rgray_p));
end

// ---- covers -------------------------------------------------------------------------------------
always @(*) begin
    cover(full_s && f_occ == 3'd4);   // the FIFO full
    cover(f_tag_taken);               // a word crossed and left through the port
    cover(f_tag_taken && wr_tok);     // ... and a reset token is written (a frame dropped)
end
