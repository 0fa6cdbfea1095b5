// feature_list's use of its FIFO (formal/run.py job feature_list_fifo): for ANY input and ANY consumer, no push
// while the FIFO is full (sync_fifo's rule; an entry would be overwritten). The finding of the feature_list job
// (a trailer or reset token pushed whatever the FIFO held) and its fix: a list end that finds the FIFO full sets
// lost_end; the token that replaces it waits for room. Header: localparam F_DEPTH.
reg f_past = 1'b0;
always @(posedge clk) f_past <= 1'b1;
always @(*) if (!f_past) assume(rst);
always @(*) if (f_past) begin
    assert(!(push && fcount == F_DEPTH));
    assert(fcount <= F_DEPTH);
    if (lost_end) assert(!accept);  // no feature listed while a lost end waits for its token
    // the FIFO's bookkeeping (invariants: the count is the LUT-RAM's words plus the head register's)
    assert(fcount == sync_fifo0_stored + fvalid && sync_fifo0_stored <= F_DEPTH);
    assert(sync_fifo0_wp == ((sync_fifo0_rp + sync_fifo0_stored) % F_DEPTH));
end
reg f_lost = 1'b0;  // an end was lost since rst
always @(posedge clk) if (rst) f_lost <= 1'b0; else if (lost_end) f_lost <= 1'b1;
always @(*) if (f_past && !rst) begin
    cover(lost_end && push);                           // the token pushed in place of the lost end
    cover(f_lost && !lost_end && accept);              // listing again after it
end
