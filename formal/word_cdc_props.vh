// Formal properties of word_cdc (formal/run.py includes this file into MyHDL's Verilog of the block,
// just before endmodule, so it sees the ports and the internal registers).
// Model: multiclock on. sclk and dclk are free inputs: any edge pattern, any frequency ratio,
// simultaneous edges included. One solver step = one tick of the global clock.

reg f_past = 1'b0;
always @($global_clock) f_past <= 1'b1;

// d is a source-domain signal: it changes only together with a rising sclk edge.
always @($global_clock) if (f_past && !$rose(sclk)) assume($stable(d));

// ---- shadow model ------------------------------------------------------------------------------
// f_cap: words captured into held (mod 4), f_cap_val: the last one; f_del: words loaded into q (mod 4).
reg [1:0] f_cap = 2'd0, f_del_r = 2'd0;  // f_del = f_del_r + this step's load
wire [1:0] f_del;
reg [$bits(d)-1:0] f_cap_val = 0;
always @(posedge sclk) if (!busy && d != held) begin
    f_cap <= f_cap + 2'd1;
    f_cap_val <= d;
end

// f_age: rising dclk edges since held last changed (saturates at 3).
// (Explicit previous-step registers: $past is allowed in clocked blocks only.)
reg [1:0] f_age_r = 2'd3;
reg [$bits(d)-1:0] f_held_p = 0;
reg f_dclk_p = 1'b0;
always @($global_clock) begin
    f_held_p <= held;
    f_dclk_p <= dclk;
end
wire f_held_changed = f_past && (held != f_held_p);
wire f_dclk_rose = f_past && dclk && !f_dclk_p;
wire [1:0] f_age = f_held_changed ? 2'd0 : ((f_age_r == 2'd3 || !f_dclk_rose) ? f_age_r : f_age_r + 2'd1);
always @($global_clock) f_age_r <= f_age;

// A load of q: the acknowledge toggles (at a dclk edge).
reg f_ack_p = 1'b0;
reg [1:0] f_cap_p = 2'd0;
reg [$bits(d)-1:0] f_cap_val_p = 0;
reg [1:0] f_age_p = 2'd3;
always @($global_clock) begin
    f_ack_p <= ack;
    f_cap_p <= f_cap;
    f_cap_val_p <= f_cap_val;
    f_age_p <= f_age;
end
wire f_load = f_past && (ack != f_ack_p);
assign f_del = f_del_r + {1'b0, f_load};
always @($global_clock) f_del_r <= f_del;

// ---- the properties -----------------------------------------------------------------------------
always @($global_clock) if (f_past) begin
    // q changes only at a load, and a load takes the newest captured word (a value d had), whole:
    if ($changed(q)) assert(f_load);
    if (f_load) begin
        assert(f_dclk_rose);
        assert(q == f_cap_val_p);
        // ... delivered exactly once and in order: it is the capture after the last one delivered
        assert(f_cap_p == f_del_r + 2'd1);
        // ... and held had been stable for two destination edges before the one that loaded it
        // (the multi-cycle path into q the docstring promises)
        assert(f_age_p >= 2'd2);
    end
end

// Invariants (they also make the induction close).
wire [5:0] f_ring = {req, req_s1, req_s2, ack, ack_s1, ack_s2};
always @(*) begin
    assert(held == f_cap_val);
    assert(ack == req_seen);
    assert(f_ring == 6'b000000 || f_ring == 6'b100000 || f_ring == 6'b110000 || f_ring == 6'b111000 ||
           f_ring == 6'b111100 || f_ring == 6'b111110 || f_ring == 6'b111111 ||
           f_ring == 6'b011111 || f_ring == 6'b001111 || f_ring == 6'b000111 ||
           f_ring == 6'b000011 || f_ring == 6'b000001);
    if (!busy) assert(f_ring == 6'b000000 || f_ring == 6'b111111);
    assert((f_cap == f_del) == (req == req_seen));
    assert(f_cap == f_del || f_cap == f_del + 2'd1);
    if (req_s1 == req && req_s1 != req_seen) assert(f_age >= 2'd1);
    if (req_s2 == req && req_s2 != req_seen) assert(f_age >= 2'd2);
end

// ---- covers -------------------------------------------------------------------------------------
reg [1:0] f_loads = 2'd0;
always @(posedge dclk) if (req_s2 != req_seen && f_loads != 2'd3) f_loads <= f_loads + 2'd1;
always @(*) begin
    cover(f_loads == 2'd2 && q != 0);             // two words crossed
    cover(busy && d != held && f_loads >= 2'd1);   // a change waits for a transfer under way
end
