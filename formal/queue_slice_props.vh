// Formal properties of queue_slice (hdl/streaming/queue_slice.py): a queue read port passed on from flip-flops.
// formal/run.py includes this file into MyHDL's Verilog of the block, just before endmodule. Data width 2.
// One clock. The queue side keeps the queue port's rule (assumed: a word offered stays, unchanged, until it
// moves); the consumer's ready is free. Asserted: the same rule on the source side, every word out is the next
// word in (none lost, duplicated or reordered), at most two words held, ready exactly while there is room,
// a word offered on the source one clock after it moved in when the slice was empty.
reg f_past = 1'b0;
always @(posedge clk) f_past <= 1'b1;
always @(*) if (!f_past) assume(rst);

// ---- the queue (sink side): a word offered stays until it moves -----------------------------------------
wire [3:0] f_in = {sink_eof, sink_eol, sink_data};
wire f_imove = sink_valid && sink_ready;
reg f_iwait = 1'b0;  // a word was offered and did not move
reg [3:0] f_iword = 0;
always @(posedge clk) begin
    f_iwait <= !rst && sink_valid && !sink_ready;
    f_iword <= f_in;
end
always @(*) if (f_past && f_iwait) assume(sink_valid && f_in == f_iword);

// ---- numbering: the n-th word in and the n-th word out (modulo 16), their words in a ghost table --------
reg [3:0] f_nin = 0, f_nout = 0;
reg [3:0] f_ghost [0:15];
wire [3:0] f_out = {source_eof, source_eol, source_data};
wire f_omove = source_valid && source_ready;
always @(posedge clk) begin
    if (rst) begin
        f_nin <= 0;
        f_nout <= 0;
    end else begin
        if (f_imove) begin
            f_ghost[f_nin] <= f_in;
            f_nin <= f_nin + 1;
        end
        if (f_omove) f_nout <= f_nout + 1;
    end
end
wire [3:0] f_held = f_nin - f_nout;  // words in the slice

always @(*) if (f_past && !rst) begin
    assert(f_held <= 2);
    assert(source_valid == (f_held != 0));             // a word held is offered
    assert(sink_ready == (f_held != 2));               // ready exactly while there is room
    assert(skid_v == (f_held == 2));
    if (source_valid) assert(f_out == f_ghost[f_nout]);  // the oldest word: in order, unaltered
    if (skid_v) assert({skid[3], skid[2], skid[1:0]} == f_ghost[f_nout + 1]);
end
// the source keeps the queue port's rule: a word offered and not taken is offered again, unchanged
reg f_owait = 1'b0;
reg [3:0] f_oword = 0;
always @(posedge clk) begin
    f_owait <= !rst && source_valid && !source_ready;
    f_oword <= f_out;
end
always @(*) if (f_past && f_owait && !rst) assert(source_valid && f_out == f_oword);
// latency: a word that moves into an empty slice is offered in the next clock
reg f_first = 1'b0;
always @(posedge clk) f_first <= !rst && f_imove && f_held == 0;
always @(*) if (f_past && f_first && !rst) assert(source_valid);

// ---- covers --------------------------------------------------------------------------------------
always @(*) begin
    cover(f_past && skid_v && f_omove);          // the skid word used: the consumer stalled, then took
    cover(f_past && f_imove && f_omove && f_held == 1 && f_nout == 4);  // full rate: one in and one out per clock
end
