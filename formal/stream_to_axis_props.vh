// Formal properties of stream_to_axis (formal/run.py includes this file into MyHDL's Verilog of the block,
// just before endmodule). Run with width=3, height=2, data_width=2, depth=4, line commit. One clock.
// The input keeps the image-stream protocol (assumed: a model of the pixel position, reset tokens at any
// time, idle cycles anywhere); tready is free (any back-pressure). Asserted on the AXI4-Stream side:
//   * a beat offered is held, payload unchanged, until it is taken (AXI4-Stream handshake rule);
//   * TLAST on every width-th beat of a line and only there;
//   * TUSER only on a line's first beat, and on the first beat after `height` whole lines (a frame cut
//     short by an overflow or a reset token ends early, never late: at most `height` lines per TUSER);
//   * nothing leaves in the clock after a reset.
// Proven by k-induction with ghost state: every word written into the FIFO carries a ghost copy of its
// input position (x, y), in a ghost memory beside the FIFO's and through the block's output stage; the
// invariants say that the words in flight (output register, skid register, RAM read register, FIFO from
// rptr to wptr) are consecutive pixels of the input (a frame may restart at a line start), with the flags
// their positions give, and that the output model and the input model sit at the two ends of that chain.
localparam F_W = 3, F_H = 2;

reg f_past = 1'b0;
always @(posedge clk) f_past <= 1'b1;
always @(*) begin
    if (!f_past) assume(rst);
    if (rst) assume(!sink_valid);
end

// ---- the input: the protocol model ----------------------------------------------------------------
reg [1:0] f_ix = 2'd0, f_iy = 2'd0;
wire f_ipix = sink_valid && (sink_eol || !sink_eof);
wire f_itok = sink_valid && sink_eof && !sink_eol;
always @(*) if (f_ipix) begin
    assume(sink_eol == (f_ix == F_W - 1));
    assume(sink_eof == (sink_eol && f_iy == F_H - 1));
end
always @(posedge clk)
    if (rst || f_itok) begin
        f_ix <= 2'd0;
        f_iy <= 2'd0;
    end else if (f_ipix) begin
        f_ix <= (f_ix == F_W - 1) ? 2'd0 : f_ix + 2'd1;
        if (f_ix == F_W - 1) f_iy <= (f_iy == F_H - 1) ? 2'd0 : f_iy + 2'd1;
    end

// ---- the AXI side ---------------------------------------------------------------------------------
reg f_wait = 1'b0;  // a beat was offered and not taken in the clock before
reg [1:0] f_data = 2'd0;
reg f_last = 1'b0, f_user = 1'b0;
always @(posedge clk) begin
    f_wait <= !rst && source_tvalid && !source_tready;
    f_data <= source_tdata;
    f_last <= source_tlast;
    f_user <= source_tuser;
end
always @(*) if (f_past && f_wait && !rst) begin
    assert(source_tvalid);
    assert(source_tdata == f_data && source_tlast == f_last && source_tuser == f_user);
end

// the output's geometry: beats in the line, whole lines since the last TUSER
reg [1:0] f_ox = 2'd0;
reg [1:0] f_oy = 2'd0;
reg f_started = 1'b0;  // a TUSER has left since rst
wire f_beat = source_tvalid && source_tready;
always @(posedge clk)
    if (rst) begin
        f_ox <= 2'd0; f_oy <= 2'd0; f_started <= 1'b0;
    end else if (f_beat) begin
        f_ox <= source_tlast ? 2'd0 : f_ox + 2'd1;
        if (source_tuser) f_started <= 1'b1;
        if (source_tlast) f_oy <= (source_tuser ? 2'd0 : f_oy) + 2'd1;
        else if (source_tuser) f_oy <= 2'd0;
    end
always @(*) if (f_past && !rst && source_tvalid) begin
    assert(source_tlast == (f_ox == F_W - 1));     // TLAST on the width-th beat of each line
    if (source_tuser) assert(f_ox == 2'd0);          // TUSER starts a line
    if (f_ox == 2'd0 && (f_oy == F_H || !f_started)) assert(source_tuser);  // at most height lines a frame
    assert(f_oy <= F_H);
end
always @(posedge clk) if (f_past && $past(rst)) assert(!source_tvalid);

// ---- ghost state: the input position of every word in flight ----------------------------------------
// a position: {y, x}; F_INIT is the position "before" the first pixel after rst (the last of a frame)
localparam [3:0] F_INIT = {2'd1, 2'd2};  // {F_H-1, F_W-1}
reg [3:0] f_gm [0:3];          // beside mem
reg [3:0] f_gq, f_gs, f_go;    // beside q, s_word, o_word
reg [3:0] f_gl = F_INIT;       // the last word taken
always @(posedge clk) begin
    if (we) f_gm[waddr] <= {f_iy, f_ix};
    if (issue) f_gq <= f_gm[raddr];
    if (!rst) begin
        if (take || !o_valid) begin
            if (s_valid) begin
                f_go <= f_gs;
                if (b_valid) f_gs <= f_gq;
            end else if (b_valid) f_go <= f_gq;
        end else if (b_valid) f_gs <= f_gq;
    end
    if (rst) f_gl <= F_INIT;
    else if (take) f_gl <= f_go;
end

// b follows a in the input: the next pixel, or a frame's first pixel at a line start
function f_succ(input [3:0] a, input [3:0] b);
    f_succ = (b[1:0] == ((a[1:0] == F_W - 1) ? 2'd0 : a[1:0] + 2'd1))
          && ((b[1:0] != 2'd0) ? (b[3:2] == a[3:2]) : (b[3:2] == 2'd0 || b[3:2] == a[3:2] + 2'd1));
endfunction
// the word's flags are the ones its position gives; the position is inside the frame
function f_word_ok(input [3:0] w, input [3:0] g);
    f_word_ok = g[1:0] < F_W && g[3:2] < F_H && w[1] == (g[1:0] == F_W - 1)
             && w[0] == (g[1:0] == 2'd0 && g[3:2] == 2'd0);
endfunction

reg f_chain;            // the words in flight are a chain of successors from f_gl
reg [3:0] f_tail;       // the last word of the chain (f_gl when none is in flight)
reg [3:0] f_ctail;      // the last committed word of the chain
reg [2:0] f_k;
reg [1:0] f_a;
integer f_i;
always @(*) begin
    f_chain = 1'b1;
    f_tail = f_gl;
    f_ctail = f_gl;
    if (o_valid) begin
        f_chain = f_chain && f_succ(f_tail, f_go) && f_word_ok(o_word, f_go);
        f_tail = f_go;
    end
    if (s_valid) begin
        f_chain = f_chain && f_succ(f_tail, f_gs) && f_word_ok(s_word, f_gs);
        f_tail = f_gs;
    end
    if (b_valid) begin
        f_chain = f_chain && f_succ(f_tail, f_gq) && f_word_ok(q, f_gq);
        f_tail = f_gq;
    end
    f_ctail = f_tail;
    for (f_i = 0; f_i < 4; f_i = f_i + 1) begin
        f_k = f_i;
        f_a = rptr[1:0] + f_k[1:0];
        if (f_k < wptr - rptr) begin
            f_chain = f_chain && f_succ(f_tail, f_gm[f_a]) && f_word_ok(mem[f_a], f_gm[f_a]);
            f_tail = f_gm[f_a];
            if (f_k < cptr - rptr) f_ctail = f_tail;
        end
    end
end

// Invariants (they make the induction close).
always @(*) if (f_past) begin
    assert(f_ix < F_W && f_iy < F_H);
    assert(wptr - rptr <= 3'd4 && cptr - rptr <= wptr - rptr);   // pointers in order, at most depth words
    assert(!s_valid || o_valid);                                  // the skid register fills behind O
    assert(!(s_valid && b_valid));                                // room for the word read
    assert(f_chain);
    assert(f_gl[1:0] < F_W && f_gl[3:2] < F_H);
    assert(f_ctail[1:0] == F_W - 1);                              // the committed words end a line
    if (dropping) assert(wptr == cptr && first);
    else begin
        assert(wptr - cptr == {1'b0, f_ix});                      // the uncommitted words: the line so far
        assert(first == (f_ix == 2'd0 && f_iy == 2'd0));
        assert(f_succ(f_tail, {f_iy, f_ix}));                     // the next pixel continues the chain
    end
    // the output model at the head of the chain
    assert(f_ox == ((f_gl[1:0] == F_W - 1) ? 2'd0 : f_gl[1:0] + 2'd1));
    if (f_started) assert(f_oy == f_gl[3:2] + (f_gl[1:0] == F_W - 1));
    else assert(f_gl == F_INIT && f_oy == 2'd0);
end

// ---- covers --------------------------------------------------------------------------------------
always @(*) if (f_past) begin
    cover(f_beat && source_tlast && f_oy == F_H - 1);  // the last line of a whole frame leaves
    cover(overflow);                                    // an overflow cut a frame
    cover(f_wait && source_tvalid && source_tlast);     // back-pressure on a line's last beat
end
