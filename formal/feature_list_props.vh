// Formal properties of feature_list (formal/run.py includes this file into MyHDL's Verilog of the block, just
// before endmodule). Run at width=3, height=3 (stereo 3x3 frames), blocks (1, 1), border 1 (pixel (1, 1) of
// each camera can be a feature: 2 beats a frame), max_features 1, depth 4. One clock.
// Assumed: rst in the first clock; no beat while rst; the sink keeps the stereo image-stream protocol (left
// then right beat of each pixel, eol/eof on both beats at the positions the beat count gives, reset tokens of
// either camera anywhere, idle cycles anywhere; the flag data free). The consumer's `ready` is free.
// Proven (k-induction, for every reachable state; the FIFO's contract assumed, see below):
//   * the queue port: a word is held (valid, data, eol, eof) until taken; words in pairs, a reset token alone
//     (one word, data 0, eof without eol); eol and eof only on a trailer's second word, eof on a token;
//   * each feature is a flag of its own list's input frame (x, y inside the border, its camera), in stream
//     order (y, x, cam strictly increasing within a list: no feature twice), at most max_features a list;
//   * each list ends with a trailer (its input frame ended with its last beat) or a token (its input frame cut
//     by a reset token), lists in input order, none out of nothing; the trailer's count is the number of
//     features that came out in the list, at most max_features and at most the frame's flags inside the
//     border; its overflow bit is set exactly when a flag of the frame was not listed;
//   * frame_done once per input frame (the clock after its last beat; never for a token); total_left,
//     total_right and count_data = the flags inside the border per camera of the last whole frame; overflow
//     = the last whole frame's overflow bit (a flag not listed).
// Invariants (they close the induction, k = 1): the FIFO's words in order continue the output list (each
// checked as above against the input's lists), the block's position (and its last-column / -row flags),
// its inside-the-border flags, counters and counter banks equal the reference's; the counter register read a
// clock ahead holds the count of the beat due.
localparam F_W = 3, F_H = 3, F_B = 1, F_MAX = 1, F_DEPTH = 4;
// An undeclared name (e.g. a register MyHDL named otherwise) is an error, not an implicit 1-bit wire.
`default_nettype none

reg f_past = 1'b0;
always @(posedge clk) f_past <= 1'b1;
always @(*) if (!f_past) assume(rst);

// ---- the input: stereo protocol (assumed), position, flags per list ---------------------------------------
reg [1:0] f_ix = 2'd0, f_iy = 2'd0;
reg f_iph = 1'b0;  // the right camera's beat is due
wire f_ipix = sink_valid && (sink_eol || !sink_eof);
wire f_itok = sink_valid && sink_eof && !sink_eol;
wire f_ilast = f_ipix && sink_eof && f_iph;  // the frame's last beat (the right camera's)
always @(*) begin
    if (rst) assume(!sink_valid);
    if (f_ipix) begin
        assume(sink_cam == f_iph);
        assume(sink_eol == (f_ix == F_W - 1));
        assume(sink_eof == (sink_eol && f_iy == F_H - 1));
    end
end
always @(posedge clk)
    if (rst || f_itok) {f_iy, f_ix, f_iph} <= 5'd0;
    else if (f_ipix) begin
        f_iph <= !f_iph;
        if (f_iph) begin
            f_ix <= (f_ix == F_W - 1) ? 2'd0 : f_ix + 2'd1;
            if (f_ix == F_W - 1) f_iy <= (f_iy == F_H - 1) ? 2'd0 : f_iy + 2'd1;
        end
    end
wire f_in = f_ix >= F_B && f_ix < F_W - F_B && f_iy >= F_B && f_iy < F_H - F_B;
wire f_flag = f_ipix && sink_data[0] && f_in;   // a feature (a flag inside the border)
wire [1:0] f_fidx = {f_ix == 2'd2, sink_cam};   // its index among the 4 possible (x 1 or 2, cam)
// Lists, numbered modulo 16 at the input (a frame's last beat or a token ends one) and at the output.
reg [3:0] f_lin = 4'd0;
reg [63:0] f_mask = 64'd0;   // list s's flags in bits [4 s +: 4] (index f_fidx)
reg [47:0] f_nflag = 48'd0;  // their number in bits [3 s +: 3]
reg [15:0] f_bytok = 16'd0;    // the list was ended by a token
wire [3:0] f_lnext = f_lin + 4'd1;
always @(posedge clk)
    if (rst) begin
        f_lin <= 4'd0; f_mask <= 64'd0; f_nflag <= 48'd0;
    end else if (f_ilast || f_itok) begin
        f_lin <= f_lnext;
        f_bytok[f_lin] <= f_itok;
        f_mask[4 * f_lnext +: 4] <= 4'd0;
        f_nflag[3 * f_lnext +: 3] <= 3'd0;
    end else if (f_flag) begin
        f_mask[4 * f_lin + f_fidx] <= 1'b1;
        f_nflag[3 * f_lin +: 3] <= f_nflag[3 * f_lin +: 3] + 3'd1;
    end
// per camera, this frame and the last whole one
reg [3:0] f_hl = 4'd0, f_hr = 4'd0, f_tl = 4'd0, f_tr = 4'd0;
reg f_fd = 1'b0;
always @(posedge clk) begin
    f_fd <= f_ilast && !rst;
    if (rst) {f_hl, f_hr, f_tl, f_tr} <= 16'd0;
    else if (f_itok) {f_hl, f_hr} <= 8'd0;
    else if (f_ilast) begin
        {f_tl, f_tr} <= {f_hl, f_hr};  // (the last beat is on the border: never a feature)
        {f_hl, f_hr} <= 8'd0;
    end else if (f_flag) begin
        if (sink_cam) f_hr <= f_hr + 4'd1;
        else f_hl <= f_hl + 4'd1;
    end
end
// the overflow bit of the last whole frame's list: a flag of it not listed (its flags != the features the
// block listed for it, which the trailer check below ties to the features that come out)
reg f_ovl = 1'b0;
always @(posedge clk) if (rst) f_ovl <= 1'b0; else if (f_ilast) f_ovl <= f_nflag[3 * f_lin +: 3] != listed;
// a consumer that has never stalled since rst
reg f_rdy = 1'b1;
always @(posedge clk) if (rst) f_rdy <= 1'b1; else if (!source_ready) f_rdy <= 1'b0;

// ---- the output: a monitor of the queue words --------------------------------------------------------------
wire f_move = source_valid && source_ready;
reg f_oh = 1'b0;            // the second word of a pair is due
reg f_okind = 1'b0;         // its pair: 0 a feature, 1 a trailer
reg [14:0] f_ox = 15'd0;    // the feature's first word
reg f_ocam = 1'b0;
reg [3:0] f_lout = 4'd0;    // the list being output
reg [2:0] f_ocnt = 3'd0;    // its features so far
reg [4:0] f_prev = 5'd0;    // the last feature's stream index {y, x, cam}
reg f_hprev = 1'b0;
reg f_hold = 1'b0;          // a word offered and not taken in the last clock
reg [15:0] f_hdata = 16'd0;
reg f_heol = 1'b0, f_heof = 1'b0;
wire [3:0] f_omask = f_mask[4 * f_lout +: 4];   // the output list's
wire [2:0] f_onflag = f_nflag[3 * f_lout +: 3];
wire f_otok = !f_oh && source_eof && !source_eol;
wire [4:0] f_oidx = {source_data[1:0], f_ox[1:0], f_ocam};
wire [1:0] f_ofidx = {f_ox == 15'd2, f_ocam};
always @(posedge clk) begin
    f_hold <= source_valid && !source_ready && !rst;
    {f_hdata, f_heol, f_heof} <= {source_data, source_eol, source_eof};
    if (rst) begin
        f_oh <= 1'b0; f_lout <= 4'd0; f_ocnt <= 3'd0; f_hprev <= 1'b0;
    end else if (f_move) begin
        if (f_otok) begin
            f_lout <= f_lout + 4'd1; f_ocnt <= 3'd0; f_hprev <= 1'b0;
        end else if (!f_oh) begin
            f_oh <= 1'b1;
            f_okind <= source_data == 16'hFFFF;
            f_ox <= source_data[14:0];
            f_ocam <= source_data[15];
        end else begin
            f_oh <= 1'b0;
            if (f_okind) begin
                f_lout <= f_lout + 4'd1; f_ocnt <= 3'd0; f_hprev <= 1'b0;
            end else begin
                f_ocnt <= f_ocnt + 3'd1; f_prev <= f_oidx; f_hprev <= 1'b1;
            end
        end
    end
end
// a word offered is held until taken
always @(*) if (f_past && !rst && f_hold)
    assert(source_valid && source_data == f_hdata && source_eol == f_heol && source_eof == f_heof);
// a first word: a token (a cut list's), a trailer's marker or a feature's x and camera
always @(*) if (f_past && !rst && source_valid && !f_oh) begin
    if (f_otok) assert(source_data == 16'd0 && f_bytok[f_lout] && f_lout != f_lin);
    else assert(!source_eol && !source_eof);
    if (!f_otok && source_data != 16'hFFFF) assert(source_data[14:0] >= F_B && source_data[14:0] < F_W - F_B);
end
// a feature's y: the feature is a flag of this list, in stream order, within max_features
always @(*) if (f_past && !rst && source_valid && f_oh && !f_okind) begin
    assert(!source_eol && !source_eof);
    assert(source_data >= F_B && source_data < F_H - F_B);
    assert(f_omask[f_ofidx]);
    if (f_hprev) assert(f_oidx > f_prev);
    assert(f_ocnt < F_MAX);
end
// a trailer's count and overflow bit
always @(*) if (f_past && !rst && source_valid && f_oh && f_okind) begin
    assert(source_eol && source_eof);
    assert(!f_bytok[f_lout] && f_lout != f_lin);  // the list's frame ended with its last beat
    assert(source_data[14:0] == f_ocnt);
    assert(f_ocnt <= F_MAX && f_ocnt <= f_onflag);
    assert(source_data[15] == (f_onflag != f_ocnt));
end
// ---- the sync FIFO's contract: the caller must not push when count == depth ---------------------------------
// Kept (feature_list_fifo proves it for any consumer). The list properties here are for consumers that let
// every list end find room: a list end that finds the FIFO full (a consumer holding `ready` low across two
// more frame ends) is replaced by a reset token when there is room (the fix of this job's finding; the
// bench regression tests/hdl/test_feature_list_sim.py covers that case).
always @(*) if (f_past) begin
    assert(!(push && fcount == F_DEPTH));
    assume(!((f_ilast || f_itok) && fcount == F_DEPTH));
    assert(!lost_end);  // so no list end is ever lost here
end

// ---- the counts and frame_done ---------------------------------------------------------
always @(*) if (f_past) begin
    assert(frame_done == f_fd);                    // once per frame, the clock after its last beat
    assert(total_left == f_tl && total_right == f_tr);
    if (count_addr == 2'd0) assert(count_data == f_tl);
    if (count_addr == 2'd1) assert(count_data == f_tr);
    assert(overflow == f_ovl);
end

// ---- invariants (they close the induction) -------------------------------------------------------------
// The FIFO's words in order (the head register, then the LUT-RAM from the read pointer) continue the output
// list: each feature a flag of its list, in stream order, within max_features; each trailer with its list's
// count and overflow bit; each token for a list cut by a token; after the last word, the input's list with the
// features the block has listed so far.
localparam F_DW = 4;  // the FIFO's depth (F_DEPTH; a separate name for the loop's index width)
reg f_fok;
reg [3:0] f_l;
reg [2:0] f_c;
reg [4:0] f_pv;
reg f_hp, f_ev;
reg [33:0] f_e;
reg [4:0] f_eidx;
integer f_j;
always @(*) begin
    f_fok = 1'b1;
    f_l = f_lout; f_c = f_ocnt; f_pv = f_prev; f_hp = f_hprev;
    for (f_j = 0; f_j <= F_DW; f_j = f_j + 1) begin
        f_ev = (f_j == 0) ? fvalid : (f_j <= sync_fifo0_stored);
        f_e = (f_j == 0) ? dout : sync_fifo0_mem[(sync_fifo0_rp + f_j - 1) % F_DW];
        f_eidx = {f_e[17:16], f_e[1:0], f_e[15]};
        if (f_ev) begin
            case (f_e[33:32])
            2'd0: begin  // a feature
                if (!(f_e[14:0] >= F_B && f_e[14:0] < F_W - F_B && f_e[31:16] >= F_B && f_e[31:16] < F_H - F_B))
                    f_fok = 1'b0;
                if (!f_mask[4 * f_l + {f_e[14:0] == 15'd2, f_e[15]}]) f_fok = 1'b0;
                if (f_hp && !(f_eidx > f_pv)) f_fok = 1'b0;
                if (!(f_c < F_MAX && f_c < f_nflag[3 * f_l +: 3])) f_fok = 1'b0;
                f_c = f_c + 3'd1; f_pv = f_eidx; f_hp = 1'b1;
            end
            2'd1: begin  // a trailer
                if (!(f_e[15:0] == 16'hFFFF && f_e[30:16] == f_c && f_e[31] == (f_nflag[3 * f_l +: 3] != f_c)
                      && f_c <= f_nflag[3 * f_l +: 3] && !f_bytok[f_l] && f_l != f_lin)) f_fok = 1'b0;
                f_l = f_l + 4'd1; f_c = 3'd0; f_hp = 1'b0;
            end
            2'd2: begin  // a token
                if (!(f_e[31:0] == 32'd0 && f_bytok[f_l] && f_l != f_lin)) f_fok = 1'b0;
                f_l = f_l + 4'd1; f_c = 3'd0; f_hp = 1'b0;
            end
            default: f_fok = 1'b0;
            endcase
        end
    end
    // the input's list: the features listed so far, all before the input's position
    if (!(f_l == f_lin && f_c == listed && (!f_hp || f_pv < {f_iy, f_ix, f_iph}))) f_fok = 1'b0;
end
wire [3:0] f_fcnt = fcnt;  // the counting bank's fresh flags
wire [3:0] f_fpub = fpub;  // the published bank's
always @(*) if (f_past) begin
    assert(f_fok);
    assert(f_ocnt <= F_MAX && f_ocnt <= f_onflag);  // the output list's features so far
    assert(x == f_ix && y == f_iy && blk == 1'b0 && f_ix < F_W && f_iy < F_H);
    assert(block_position0_bx == 1'b0 && block_position0_by == 1'b0 && block_position0_base == 1'b0);  // one block
    // the last-column / -row flags (one block: its last column / row is the frame's)
    assert(block_position0_xe == (f_ix == F_W - 1) && block_position0_xw == (f_ix == F_W - 1));
    assert(block_position0_ye == (f_iy == F_H - 1) && block_position0_yh == (f_iy == F_H - 1));
    assert(inx == (f_ix >= F_B && f_ix < F_W - F_B) && iny == (f_iy >= F_B && f_iy < F_H - F_B));  // the border
    // the FIFO's bookkeeping
    assert(fcount == sync_fifo0_stored + fvalid && sync_fifo0_stored <= F_DW);
    assert(sync_fifo0_wp == ((sync_fifo0_rp + sync_fifo0_stored) % F_DW));
    // the serializer: the head's first word gone
    assert(half == f_oh);
    if (f_oh) assert(fvalid && dout[33:32] != 2'd2 && f_okind == (dout[33:32] == 2'd1));
    if (f_oh && !f_okind) assert(f_ox == dout[14:0] && f_ocam == dout[15]);
    if (f_hold) assert(fvalid);
    // the list being filled
    assert(listed <= F_MAX && ovf == (f_nflag[3 * f_lin +: 3] != listed));
    // the counters: the counting bank = this frame's flags, the published one = the last whole frame's
    assert(tot0 == f_hl && tot1 == f_hr);
    assert((f_fcnt[0] ? cmem[{bank, 2'b00}] : 4'd0) == f_hl && (f_fcnt[1] ? cmem[{bank, 2'b01}] : 4'd0) == f_hr);
    assert((f_fpub[0] ? cmem[{!bank, 2'b00}] : 4'd0) == f_tl && (f_fpub[1] ? cmem[{!bank, 2'b01}] : 4'd0) == f_tr);
    // the counter of the beat due (its camera the one after the last beat's), read a clock ahead
    assert(due == f_iph && cur == (f_iph ? f_hr : f_hl));
    assert(f_hl <= 4'd1 && f_hr <= 4'd1 && f_tl <= 4'd1 && f_tr <= 4'd1);  // one pixel inside the border
    assert(f_nflag[3 * f_lin +: 3] == f_hl + f_hr && f_mask[4 * f_lin +: 4] == {2'b00, f_hr[0], f_hl[0]});
    if (f_hl) assert({f_iy, f_ix, f_iph} > {2'd1, 2'd1, 1'b0});  // the flags of this frame: beats gone by
    if (f_hr) assert({f_iy, f_ix, f_iph} > {2'd1, 2'd1, 1'b1});
    assert(fcount <= F_DEPTH);
end

// ---- covers ----------------------------------------------------------------------------------------------
always @(*) if (f_past && !rst) begin
    cover(f_move && f_oh && f_okind && source_data[15] && source_data[14:0] == F_MAX);  // a full list, overflow
    cover(f_move && f_oh && f_okind && f_lout == 4'd1);   // the second list's trailer
    cover(f_move && f_otok);                               // a cut list's token
    cover(frame_done && total_left == 4'd1 && total_right == 4'd1);  // every feature of a frame
    cover(f_move && f_oh && !f_okind && f_ocam);                     // a right camera's feature
    cover(f_move && f_oh && f_okind && !f_rdy && source_data[15] && source_data[14:0] < F_MAX);  // a FIFO drop
end
