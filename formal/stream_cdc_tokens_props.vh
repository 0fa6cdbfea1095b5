// stream_cdc's mapping of beats to the FIFO's words and back (formal/run.py includes this file into
// MyHDL's Verilog of stream_cdc, stereo, data_width=2: FIFO words of 5 data bits {eof, eol, cam, data}).
// With async_fifo_frames (the FIFO delivers each pixel word as written, and a token only to close a frame
// cut after a prefix of its words) this shows that no pixel becomes a reset token and no token a pixel:
//   * write side: a sink pixel is a FIFO pixel, a sink reset token a FIFO token, and the word's data
//     field is the beat {eof, eol, cam, data} unchanged; the FIFO's frame ends with the right beat;
//   * read side: for any word the FIFO can present, a FIFO token goes out as a reset token; a FIFO pixel
//     whose data field is a pixel beat with the flags the write side gives it goes out as exactly that
//     beat (the stored word is free here: q is any state, so the induction closes at once).
wire f_spix = sink_valid && (sink_eol || !sink_eof), f_stok = sink_valid && sink_eof && !sink_eol;
wire f_fpix = fin_valid && (fin_eol || !fin_eof), f_ftok = fin_valid && fin_eof && !fin_eol;
wire f_qpix = q_valid && (q_eol || !q_eof), f_qtok = q_valid && q_eof && !q_eol;
wire f_opix = source_valid && (source_eol || !source_eof), f_otok = source_valid && source_eof && !source_eol;
wire f_beof = q_data[4], f_beol = q_data[3], f_bcam = q_data[2];  // the beat stored in the word
always @(*) begin
    // write side
    assert(fin_valid == sink_valid && f_fpix == f_spix && f_ftok == f_stok);
    assert(fin_data == {sink_eof, sink_eol, sink_cam, sink_data});
    if (f_spix) assert(fin_eol == (sink_eol && sink_cam) && fin_eof == (sink_eof && sink_cam));
    // read side
    assert(source_valid == q_valid);
    if (f_qtok) assert(f_otok);
    if (f_qpix && (f_beol || !f_beof) && q_eol == (f_beol && f_bcam) && q_eof == (f_beof && f_bcam))
        assert(f_opix && {source_eof, source_eol, source_cam, source_data} == q_data);
end
always @(*) begin
    cover(f_otok);
    cover(f_opix && source_eof && source_cam);
    cover(f_opix && source_eof && !source_cam);
end
