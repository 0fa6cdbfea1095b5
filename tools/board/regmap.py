"""The board's own registers (the ULX3S design's), beside the front end's map on the UART bridge's bus.

The UART bridge's bus has 24 address bits: bit 23 = 0 reaches the front end's register map
(:data:`eyestereo.tools.regmap.REGMAP`, docs/registers.md), bit 23 = 1 these registers
(:func:`eyestereo.hdl.boards.board_regs.board_regs`); :data:`BOARD_BASE` is the bus address of their offset 0.
"""

from __future__ import annotations

from eyestereo.tools.regmap import Field, Register, RegisterMap

__all__ = ["BOARD_BASE", "BOARD_REGMAP", "BOARD_ID"]

#: Bus address of the board's register 0 on the bridge's bus (address bit 23).
BOARD_BASE = 1 << 23
#: BOARD_ID's value: 'E' 'B' (eyestereo board) and this map's version.
BOARD_ID = 0x45420001

BOARD_REGISTERS = (
    Register("BOARD_ID", 0x00, "const", "identification: 'EB' and the board map's version",
             (Field("board_id", 0, 32, "0x4542_0001", reset=BOARD_ID),)),
    Register("BOARD_CTRL", 0x04, "rw", "the monitor picture",
             (Field("display_run", 0, 1, "1: the display takes the newest pair every frame; 0: it keeps the last "
                    "one (and leaves the buffer handshake to the host)", reset=1),)),
    Register("BOARD_CMD", 0x08, "pulse", "commands (write 1 to act)",
             (Field("sccb_restart", 0, 1, "write the cameras' register table again"),)),
    Register("BOARD_STATUS", 0x0C, "status", "the board's state",
             (Field("pll_locked", 0, 1, "the PLL is locked"),
              Field("sccb_busy", 1, 1, "the cameras' register table is being written"),
              Field("cam_present", 2, 2, "bit c: camera c (0 left, 1 right) answered with the OV7670's IDs"),
              Field("display_idle", 4, 1, "the display holds no buffer and wants none (display_run 0: the host "
                    "may take pairs itself)"),
              Field("copies", 16, 16, "pairs the display has copied since reset (wraps)"))),
    Register("BOARD_ERRORS", 0x10, "status", "the serial link's faults",
             (Field("uart_errors", 0, 16, "framing errors, unknown and abandoned requests (saturates)"),)),
    Register("BOARD_CLOCKS", 0x14, "const", "the clocks the bitstream was built for (MHz)",
             (Field("mem_mhz", 0, 8, "memory clock", param="mem_mhz"),
              Field("harris_mhz", 8, 8, "Harris clock", param="harris_mhz"),
              Field("pixel_mhz", 16, 8, "pixel clock", param="pixel_mhz"),
              Field("tmds_mhz", 24, 8, "TMDS bit clock (two bits a clock)", param="tmds_mhz"))),
)

BOARD_REGMAP = RegisterMap(BOARD_REGISTERS, local_bytes=0x20)
