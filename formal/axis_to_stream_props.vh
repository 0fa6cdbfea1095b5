// Formal properties of axis_to_stream (formal/run.py includes this file into MyHDL's Verilog of the block,
// just before endmodule). Run with width=3, height=2 (3x2 frames), data_width=2. One clock.
// The AXI4-Stream input is free: any tvalid, tuser, tlast, tdata on any clock (a master that breaks the
// AXI rules too). Asserted:
//   * the image stream out keeps its protocol (a model of the output's frame position, reset by tokens
//     and rst): eol exactly on every width-th pixel of a line, eof with eol exactly on the last line's;
//   * tready is high except in the clock after rst and in the clock after an early SOF (the slave's side
//     of the handshake: the bridge takes a transfer whenever it can, the image stream cannot wait);
//   * a reference bridge written from the docstring (frame position, "in a frame", "synced", the held SOF
//     pixel) and the block agree on every clock: each accepted pixel leaves one clock later with its data
//     and the eol/eof its position gives; a line ending early or late and an SOF inside a frame leave
//     as a reset token with an `error` pulse; transfers outside a frame are dropped (with one `error`
//     pulse after a whole frame, none after rst or a fault); no beat and no error otherwise.
localparam F_W = 3, F_H = 2;

reg f_past = 1'b0;
always @(posedge clk) f_past <= 1'b1;
always @(*) if (!f_past) assume(rst);

// ---- the output protocol ----------------------------------------------------------------------------
reg [1:0] f_ox = 2'd0, f_oy = 2'd0;
wire f_opix = source_valid && (source_eol || !source_eof);
wire f_otok = source_valid && source_eof && !source_eol;
always @(posedge clk)
    if (rst || f_otok) begin
        f_ox <= 2'd0;
        f_oy <= 2'd0;
    end else if (f_opix) begin
        f_ox <= (f_ox == F_W - 1) ? 2'd0 : f_ox + 2'd1;
        if (f_ox == F_W - 1) f_oy <= (f_oy == F_H - 1) ? 2'd0 : f_oy + 2'd1;
    end
always @(*) if (f_past && f_opix) begin
    assert(source_eol == (f_ox == F_W - 1));
    assert(source_eof == (source_eol && f_oy == F_H - 1));
end

// ---- the reference bridge ---------------------------------------------------------------------------
reg [1:0] f_x = 2'd0, f_y = 2'd0;   // the next pixel's position in the frame in progress
reg f_inf = 1'b0;                    // a frame is in progress
reg f_sync = 1'b0;                   // an SOF was seen since rst or the last fault
reg f_held = 1'b0;                   // the SOF pixel of an early SOF waits (tready low)
reg [1:0] f_hdata = 2'd0;
reg f_rst_p = 1'b1;
wire f_ready = !f_rst_p && !f_held;
wire f_xfer = sink_tvalid && f_ready;
// this clock's pixel position: (0, 0) for an SOF
wire [1:0] f_px = (sink_tuser && !f_held) ? 2'd0 : f_x;
wire [1:0] f_py = (sink_tuser && !f_held) ? 2'd0 : f_y;
// the beat expected one clock later
reg f_ev, f_eeol, f_eeof, f_eerr;
reg [1:0] f_edata;
reg f_emit;  // a pixel leaves (from the held word or a transfer)
always @(*) begin
    f_ev = 1'b0; f_eeol = 1'b0; f_eeof = 1'b0; f_eerr = 1'b0; f_edata = 2'd0; f_emit = 1'b0;
    if (f_held) begin
        f_emit = 1'b1; f_edata = f_hdata;
    end else if (f_xfer) begin
        if (sink_tuser && f_inf) begin                          // early SOF: a token now, the pixel next
            f_ev = 1'b1; f_eeof = 1'b1; f_eerr = 1'b1;
        end else if (sink_tuser || f_inf) begin
            if (sink_tlast != (f_px == F_W - 1)) begin          // short or long line: a token
                f_ev = 1'b1; f_eeof = 1'b1; f_eerr = 1'b1;
            end else begin
                f_emit = 1'b1; f_edata = sink_tdata[1:0];
            end
        end else if (f_sync)                                    // a line after a whole frame
            f_eerr = 1'b1;
    end
    if (f_emit) begin
        f_ev = 1'b1;
        f_eeol = (f_px == F_W - 1);
        f_eeof = (f_px == F_W - 1) && (f_py == F_H - 1);
    end
end
always @(posedge clk) begin
    f_rst_p <= rst;
    if (rst) begin
        f_x <= 2'd0; f_y <= 2'd0; f_inf <= 1'b0; f_sync <= 1'b0; f_held <= 1'b0;
    end else begin
        if (f_held) f_held <= 1'b0;
        else if (f_xfer) begin
            if (sink_tuser && f_inf) begin
                f_held <= 1'b1; f_hdata <= sink_tdata[1:0];
                f_inf <= 1'b0; f_sync <= 1'b1; f_x <= 2'd0; f_y <= 2'd0;
            end else if (sink_tuser || f_inf) begin
                if (sink_tuser) f_sync <= 1'b1;
                if (!f_emit) begin f_inf <= 1'b0; f_sync <= 1'b0; end
            end else if (f_sync) f_sync <= 1'b0;
        end
        if (f_emit) begin
            f_inf <= !f_eeof;
            f_x <= (f_px == F_W - 1) ? 2'd0 : f_px + 2'd1;
            f_y <= (f_px != F_W - 1) ? f_py : (f_py == F_H - 1) ? 2'd0 : f_py + 2'd1;
        end
    end
end
reg f_ev_p = 1'b0, f_eeol_p = 1'b0, f_eeof_p = 1'b0, f_eerr_p = 1'b0;
reg [1:0] f_edata_p = 2'd0;
always @(posedge clk) begin
    f_ev_p <= f_ev && !rst; f_eeol_p <= f_eeol; f_eeof_p <= f_eeof; f_eerr_p <= f_eerr && !rst;
    f_edata_p <= f_edata;
end

reg [1:0] f_xd = 2'd0, f_yd = 2'd0;
reg f_infd = 1'b0;
always @(posedge clk) begin
    f_xd <= f_x; f_yd <= f_y; f_infd <= f_inf && !rst;
end

// ---- the block agrees ---------------------------------------------------------------------------------
always @(*) if (f_past) begin
    assert(sink_tready == f_ready);
    assert(source_valid == f_ev_p);
    assert(error == f_eerr_p);
    if (source_valid) begin
        assert(source_eol == f_eeol_p && source_eof == f_eeof_p);
        if (!source_eof || source_eol) assert(source_data == f_edata_p);   // a pixel: its data
    end
end
// Invariants (they make the induction close): the block's state is the reference's.
always @(*) if (f_past) begin
    assert(x == f_x && y == f_y && f_x < F_W && f_y < F_H);
    assert(in_frame == f_inf && synced == f_sync && held == f_held);
    if (held) assert(held_data == f_hdata);
    if (f_held) assert(!f_inf && f_x == 2'd0 && f_y == 2'd0);
    // the output model is where the reference was one clock before (the beat's latency): in a frame at its
    // position, else at a frame's start
    if (f_infd) assert(f_ox == f_xd && f_oy == f_yd);
    else assert(f_ox == 2'd0 && f_oy == 2'd0);
    if (f_rst_p) assert(!f_held && !f_inf);
end

// ---- covers --------------------------------------------------------------------------------------
reg f_frame = 1'b0;  // a whole frame left since rst
always @(posedge clk) if (rst) f_frame <= 1'b0; else if (f_opix && source_eof) f_frame <= 1'b1;
always @(*) if (f_past) begin
    cover(f_opix && source_eof);                         // a whole frame out
    cover(f_held && f_frame);                            // an early SOF after a whole frame
    cover(f_otok && f_frame && !f_eeol_p && f_oy == 2'd1);  // a token in a frame's second line
    cover(error && !source_valid);                       // a line after a whole frame (too many lines)
end
