r"""A MyHDL bench top for fast whole-system runs: stereo_frontend with its cameras and SRAM as HDL test models.

The per-clock work of :mod:`eyestereo.sim.benches.tb_stereo_frontend` (Python camera models, the Python SRAM
model, a cocotbext-axi host waking on every clock) moves into the simulator here: two *camera players* and an
*SRAM part* written in VHDL and Verilog (this module's :data:`MODELS`, hand-written test models, not FPGA blocks)
sit beside the converted top in one simulation, and Python wakes only to write a camera script, start, poll the
registers now and then, and read a buffer back. The bench is :mod:`eyestereo.sim.benches.tb_frontend_fast`.

Camera player (``camera_player``, one per camera)
    Plays a camera *script* file (:func:`eyestereo.sim.lib.fast_system.write_script`) on the camera's pins,
    clocked by a free-running ``base`` clock from the bench: PCLK is ``base`` gated (stopped during a ``stop``
    run), the bus changes after the falling edge of ``base`` and is stable at PCLK's rising edge, as the OV6630
    (and the Python :class:`~eyestereo.sim.lib.camera.CameraModel`) does. The script is a list of runs, one
    decimal integer per line: a header ``kind * 2**24 + n`` (kind 1 VSYNC active for n PCLK, 2 blanking for n
    PCLK, 3 a line of n bytes with HREF active, followed by ceil(n / 3) words of 3 bytes each, first byte in the
    low bits, 4 PCLK stopped for n periods of ``base``), then the next run; at the end of the file the bus idles
    (PCLK running) and ``done`` rises. ``samples`` counts the base periods played. The player opens its script
    when ``go`` rises (the bench writes the scripts first; until then PCLK runs with the bus idle, so the camera
    domain's synchronous reset is seen).

    Timing (PCLK = base while running; a column per base period; the bus set after base's falling edge)::

        base   _/~\_/~\_/~\_/~\_/~\_/~\_/~\_
        pclk   _/~\_/~\_/~\_____________/~\_      (a ``stop`` run of 2: no rising edge)
        href   ____/~~~~~~~~~~~~~~~~~~~~~~~~~~      (a ``line`` run: HREF active from its first byte)
        data   ====X b0X b1X b1    b1    X b2X      (the bus holds its value while PCLK stops)

SRAM part (``sram_part``)
    The board's NoBL (ZBT) SRAM, 1M x 16, read latency ``RL`` (1..3): the same part and rules as
    :class:`~eyestereo.tools.sram.SramChip` (``kind="nobl"``), checked at every rising edge: (1) single accesses
    only (``ld_n`` low), (2) byte writes (a write enables a byte), (3) write data in the right cycle (the FPGA
    drives DQ exactly in the cycle before the edge that samples a write's data; a stray drive or a missing one
    breaks it), (4) no bus contention (the FPGA never drives while the part does), (5) output enable (``oe_n``
    low in every cycle the part drives read data), and, in the VHDL (the Verilog is two-valued on Verilator),
    (0) inputs defined. A broken rule is counted (``viol_count``), the first one's rule and edge kept
    (``viol_rule``, ``viol_edge``), every rule seen marked in ``viol_rules`` (bit r for rule r) and the first
    four printed. Reads see every write registered before them (the NoBL part forwards), a word never written
    reads as :func:`~eyestereo.tools.sram.power_up_word`. ``reads`` and ``writes`` count the accesses.

    Backdoor read (for verification where the bus read-out is not what is tested): the bench sets
    ``dump_addr`` and ``dump_len`` and toggles ``dump_stb``; at the next rising edge the part writes those words
    (one decimal per line) to ``sram_dump.txt`` (:data:`~eyestereo.sim.lib.harness_files.DUMP_FILE`) in the run
    folder and copies ``dump_stb`` to ``dump_ack``.

FIFO watch (``fifo_watch``, one per camera FIFO, MyHDL test logic)
    The highest fill level of each camera's async FIFO since the bench last toggled ``fifo_clear``
    (``cam_l_fifo_max``, ``cam_r_fifo_max``), from the FIFO's own write pointer and synchronised read pointer (the
    signals its ``full`` flag compares), found in the elaborated top: the soak's coverage of FIFO levels.

Ports of the harness: the top's ``clk, rst, hclk, hrst, wrst_l, wrst_r, bus`` (unchanged), the cameras' base
clocks ``base_l, base_r``, ``cam_go`` (the players start their scripts), and the test models' ports above
(``cam_l_done``, ``cam_l_samples``, ..., ``sram_*``, ``fifo_clear``, ``cam_*_fifo_max``). Registered as the
simulation-only catalogue top ``frontend_harness``; its parameters are
stereo_frontend's (the SRAM part must be ``kind="nobl"``, ``memory="sram"``).
"""

from __future__ import annotations

from myhdl import ResetSignal, Signal, always, always_comb, block, intbv

from eyestereo.hdl.flow.catalog import BENCH_TOPS, BlockSpec, block_defaults
from eyestereo.hdl.interfaces.axil import AxiLite
from eyestereo.hdl.interfaces.camera_bus import CameraBus
from eyestereo.hdl.interfaces.sram_bus import SramPins
from eyestereo.hdl.system.stereo_frontend import stereo_frontend
from eyestereo.sim.lib.harness_files import SCRIPT_FILES
from eyestereo.tools.regmap import REGMAP

NAME = "frontend_harness"

CAMERA_PLAYER_V = r"""
// camera_player: plays a camera bus script (eyestereo.sim.harnesses.frontend_harness) - a test model.
module camera_player #(parameter FILE = "cam.txt", parameter VSYNC_ACTIVE = 1, parameter HREF_ACTIVE = 1) (
    input wire base, input wire go, output wire pclk, output reg vsync, output reg href,
    output reg [7:0] data, output reg done, output reg [31:0] samples);
  integer fd, r, w, kind, left, nb, word;
  reg en, opened;
  initial begin
    kind = 0; left = 0; nb = 0; word = 0; en = 1'b1; opened = 1'b0; done = 1'b0; samples = 0;
    vsync = !VSYNC_ACTIVE; href = !HREF_ACTIVE; data = 8'd0;
  end
  // en changes while base is low: PCLK never glitches
  assign pclk = base & en;
  always @(negedge base) begin
    if (!opened) begin
      // PCLK runs (idle bus) until the bench has written the script and raised go
      if (go) begin
        fd = $fopen(FILE, "r");
        if (fd == 0) begin
          $display("camera_player: cannot open %s", FILE);
          $finish;
        end
        opened = 1'b1;
      end
    end else if (!done) begin
      if (left == 0) begin
        r = $fscanf(fd, "%d\n", w);
        if (r != 1) begin
          kind = 0; left = 1;
        end else begin
          kind = w / 16777216; left = w % 16777216; nb = 0;
        end
      end
      if (kind == 1 || kind == 2) begin
        vsync <= (kind == 1) ? VSYNC_ACTIVE : !VSYNC_ACTIVE;
        href <= !HREF_ACTIVE;
        data <= 8'd0;
        en <= 1'b1;
      end else if (kind == 3) begin
        if (nb == 0) begin
          r = $fscanf(fd, "%d\n", word);
          nb = 3;
        end
        vsync <= !VSYNC_ACTIVE;
        href <= HREF_ACTIVE;
        data <= word % 256;
        word = word / 256;
        nb = nb - 1;
        en <= 1'b1;
      end else if (kind == 4) begin
        en <= 1'b0;
      end else begin
        vsync <= !VSYNC_ACTIVE;
        href <= !HREF_ACTIVE;
        data <= 8'd0;
        en <= 1'b1;
        done <= 1'b1;
        $fclose(fd);
      end
      left = left - 1;
      samples <= samples + 1;
    end
  end
endmodule
"""

CAMERA_PLAYER_VHDL = r"""
-- camera_player: plays a camera bus script (eyestereo.sim.harnesses.frontend_harness) - a test model.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use std.textio.all;

entity camera_player is
    generic (FILE_NAME: string := "cam.txt"; VSYNC_ACTIVE: integer := 1; HREF_ACTIVE: integer := 1);
    port (base: in std_logic; go: in std_logic; pclk: out std_logic; vsync: out std_logic; href: out std_logic;
          data: out unsigned(7 downto 0); done: out std_logic; samples: out unsigned(31 downto 0));
end entity camera_player;

architecture model of camera_player is
    signal en: std_logic := '1';
    function lvl(b: integer) return std_logic is
    begin
        if b = 1 then
            return '1';
        end if;
        return '0';
    end function;
begin
    -- en changes while base is low: PCLK never glitches
    pclk <= base and en;

    play: process
        file f: text;
        variable st: file_open_status;
        variable l: line;
        variable w, kind, left, nb, word, n: integer;
    begin
        vsync <= not lvl(VSYNC_ACTIVE);
        href <= not lvl(HREF_ACTIVE);
        data <= (others => '0');
        done <= '0';
        samples <= (others => '0');
        -- PCLK runs (idle bus) until the bench has written the script and raised go
        wait until falling_edge(base) and go = '1';
        file_open(st, f, FILE_NAME, read_mode);
        assert st = open_ok report "camera_player: cannot open " & FILE_NAME severity failure;
        kind := 0; left := 0; nb := 0; word := 0; n := 0;
        loop
            if left = 0 then
                if endfile(f) then
                    kind := 0;
                    left := 1;
                else
                    readline(f, l);
                    read(l, w);
                    kind := w / 16777216;
                    left := w mod 16777216;
                    nb := 0;
                end if;
            end if;
            n := n + 1;
            samples <= to_unsigned(n, 32);
            if kind = 1 or kind = 2 then
                if kind = 1 then
                    vsync <= lvl(VSYNC_ACTIVE);
                else
                    vsync <= not lvl(VSYNC_ACTIVE);
                end if;
                href <= not lvl(HREF_ACTIVE);
                data <= (others => '0');
                en <= '1';
            elsif kind = 3 then
                if nb = 0 then
                    readline(f, l);
                    read(l, word);
                    nb := 3;
                end if;
                vsync <= not lvl(VSYNC_ACTIVE);
                href <= lvl(HREF_ACTIVE);
                data <= to_unsigned(word mod 256, 8);
                word := word / 256;
                nb := nb - 1;
                en <= '1';
            elsif kind = 4 then
                en <= '0';
            else
                vsync <= not lvl(VSYNC_ACTIVE);
                href <= not lvl(HREF_ACTIVE);
                data <= (others => '0');
                en <= '1';
                done <= '1';
                file_close(f);
                exit;
            end if;
            left := left - 1;
            wait until falling_edge(base);
        end loop;
        wait;
    end process;
end architecture model;
"""

SRAM_PART_V = r"""
// sram_part: the board's NoBL SRAM (1M x 16), its rules checked at every edge - a test model.
module sram_part #(parameter RL = 2) (
    input wire clk, input wire [19:0] addr, input wire ce_n, input wire ld_n, input wire we_n,
    input wire [1:0] bw_n, input wire oe_n, input wire [15:0] dq_o, input wire dq_oe, output reg [15:0] dq_i,
    input wire dump_stb, input wire [19:0] dump_addr, input wire [20:0] dump_len, output reg dump_ack,
    output reg [31:0] viol_count, output reg [3:0] viol_rule, output reg [31:0] viol_edge,
    output reg [7:0] viol_rules, output reg [31:0] reads, output reg [31:0] writes);
  reg [15:0] mem [0:1048575];
  reg written [0:1048575];
  // pipelines: slot k is due k edges from now (writes: data sampled; reads: data driven)
  reg wv [0:3]; reg [19:0] wa [0:3]; reg [1:0] wb [0:3];
  reg rv [0:3]; reg [19:0] ra [0:3];
  reg drove;
  integer edge_n, k, fd, i;
  reg [15:0] v;

  function [15:0] power_up(input [19:0] a);
    reg [31:0] x;
    begin
      x = {12'd0, a} * 32'h9E3779B1 + 32'h7F4A7C15;
      x = x ^ (x >> 15);
      x = x * 32'h2C1B3C6D;
      x = x ^ (x >> 12);
      power_up = x[15:0];
    end
  endfunction

  function [15:0] word_at(input [19:0] a);
    begin
      word_at = written[a] ? mem[a] : power_up(a);
    end
  endfunction

  task violate(input integer rule);
    begin
      if (viol_count < 4)
        $display("sram_part: rule %0d (%s) broken at edge %0d", rule,
                 rule == 1 ? "single accesses only" : rule == 2 ? "byte writes" :
                 rule == 3 ? "write data in the right cycle" : rule == 4 ? "no bus contention" : "output enable",
                 edge_n);
      if (viol_count == 0) begin
        viol_rule = rule;
        viol_edge = edge_n;
      end
      viol_count = viol_count + 1;
      viol_rules = viol_rules | (8'd1 << rule);
    end
  endtask

  initial begin
    for (i = 0; i < 1048576; i = i + 1) written[i] = 1'b0;
    for (k = 0; k < 4; k = k + 1) begin wv[k] = 1'b0; rv[k] = 1'b0; wa[k] = 0; ra[k] = 0; wb[k] = 0; end
    drove = 1'b0; edge_n = 0; dq_i = 16'd0; dump_ack = 1'b0;
    viol_count = 0; viol_rule = 0; viol_edge = 0; viol_rules = 0; reads = 0; writes = 0;
  end

  always @(posedge clk) begin
    edge_n = edge_n + 1;
    for (k = 0; k < 3; k = k + 1) begin
      wv[k] = wv[k + 1]; wa[k] = wa[k + 1]; wb[k] = wb[k + 1];
      rv[k] = rv[k + 1]; ra[k] = ra[k + 1];
    end
    wv[3] = 1'b0; rv[3] = 1'b0;
    // the rules, on the pins the FPGA set during the cycle that ends at this edge
    if (ld_n != 1'b0) violate(1);
    if (ce_n == 1'b0 && we_n == 1'b0 && bw_n == 2'b11) violate(2);
    if (dq_oe && !wv[0]) violate(3);
    if (wv[0] && !dq_oe) violate(3);
    if (dq_oe && drove) violate(4);
    if (drove && oe_n != 1'b0) violate(5);
    // the write whose data this edge samples
    if (wv[0]) begin
      v = word_at(wa[0]);
      if (!wb[0][0]) v[7:0] = dq_o[7:0];
      if (!wb[0][1]) v[15:8] = dq_o[15:8];
      mem[wa[0]] = v;
      written[wa[0]] = 1'b1;
    end
    // the access registered at this edge
    if (ce_n == 1'b0) begin
      if (we_n == 1'b0) begin
        wv[RL] = 1'b1; wa[RL] = addr; wb[RL] = bw_n;
        writes = writes + 1;
      end else begin
        rv[RL - 1] = 1'b1; ra[RL - 1] = addr;
        reads = reads + 1;
      end
    end
    // the read data the part drives in the cycle after this edge
    if (rv[0]) begin
      dq_i <= word_at(ra[0]);
      drove = 1'b1;
    end else begin
      dq_i <= 16'd0;
      drove = 1'b0;
    end
    if (dump_stb != dump_ack) begin
      fd = $fopen("sram_dump.txt", "w");
      for (i = 0; i < dump_len; i = i + 1) $fdisplay(fd, "%0d", word_at(dump_addr + i));
      $fclose(fd);
      dump_ack <= dump_stb;
    end
  end
endmodule
"""

SRAM_PART_VHDL = r"""
-- sram_part: the board's NoBL SRAM (1M x 16), its rules checked at every edge - a test model.
library ieee;
use ieee.std_logic_1164.all;
use ieee.numeric_std.all;
use std.textio.all;

entity sram_part is
    generic (RL: integer := 2);
    port (clk: in std_logic; addr: in unsigned(19 downto 0); ce_n: in std_logic; ld_n: in std_logic;
          we_n: in std_logic; bw_n: in unsigned(1 downto 0); oe_n: in std_logic; dq_o: in unsigned(15 downto 0);
          dq_oe: in std_logic; dq_i: out unsigned(15 downto 0) := (others => 'Z');
          dump_stb: in std_logic; dump_addr: in unsigned(19 downto 0); dump_len: in unsigned(20 downto 0);
          dump_ack: out std_logic := '0';
          viol_count: out unsigned(31 downto 0) := (others => '0'); viol_rule: out unsigned(3 downto 0) := "0000";
          viol_edge: out unsigned(31 downto 0) := (others => '0'); viol_rules: out unsigned(7 downto 0) := x"00";
          reads: out unsigned(31 downto 0) := (others => '0'); writes: out unsigned(31 downto 0) := (others => '0'));
end entity sram_part;

architecture model of sram_part is
    type rule_names_t is array (0 to 5) of string(1 to 29);
    constant RULE_NAMES: rule_names_t := ("inputs defined               ", "single accesses only         ",
                                          "byte writes                  ", "write data in the right cycle",
                                          "no bus contention            ", "output enable                ");

    function power_up(a: natural) return natural is
        variable x: unsigned(31 downto 0);
    begin
        x := resize(to_unsigned(a, 32) * unsigned'(x"9E3779B1"), 32) + unsigned'(x"7F4A7C15");
        x := x xor shift_right(x, 15);
        x := resize(x * unsigned'(x"2C1B3C6D"), 32);
        x := x xor shift_right(x, 12);
        return to_integer(x(15 downto 0));
    end function;

    function undefined(v: std_logic) return boolean is
    begin
        return v /= '0' and v /= '1';
    end function;

    function undefined(v: unsigned) return boolean is
    begin
        for i in v'range loop
            if v(i) /= '0' and v(i) /= '1' then
                return true;
            end if;
        end loop;
        return false;
    end function;
begin
    part: process (clk)
        type mem_t is array (0 to 2**20 - 1) of natural range 0 to 65535;
        type bool_t is array (0 to 2**20 - 1) of boolean;
        type slot_b is array (0 to 3) of boolean;
        type slot_n is array (0 to 3) of natural;
        variable mem: mem_t;
        variable written: bool_t := (others => false);
        variable wv, rv: slot_b := (others => false);
        variable wa, wb, ra: slot_n := (others => 0);
        variable drove: boolean := false;
        variable edge_n, count, rules, n_reads, n_writes: natural := 0;
        variable v, lo, hi, a: natural;
        variable ack: std_logic := '0';
        variable l: line;
        file f: text;

        impure function word_at(x: natural) return natural is
        begin
            if written(x) then
                return mem(x);
            end if;
            return power_up(x);
        end function;

        procedure violate(rule: natural) is
        begin
            if count < 4 then
                report "sram_part: rule " & integer'image(rule) & " (" & RULE_NAMES(rule) & ") broken at edge "
                    & integer'image(edge_n) severity warning;
            end if;
            if count = 0 then
                viol_rule <= to_unsigned(rule, 4);
                viol_edge <= to_unsigned(edge_n, 32);
            end if;
            count := count + 1;
            if (rules / 2**rule) mod 2 = 0 then
                rules := rules + 2**rule;
            end if;
            viol_count <= to_unsigned(count, 32);
            viol_rules <= to_unsigned(rules, 8);
        end procedure;
    begin
        if rising_edge(clk) then
            edge_n := edge_n + 1;
            for k in 0 to 2 loop
                wv(k) := wv(k + 1); wa(k) := wa(k + 1); wb(k) := wb(k + 1);
                rv(k) := rv(k + 1); ra(k) := ra(k + 1);
            end loop;
            wv(3) := false;
            rv(3) := false;
            -- the rules, on the pins the FPGA set during the cycle that ends at this edge
            if undefined(ld_n) or undefined(ce_n) or undefined(dq_oe) then
                violate(0);
            elsif ce_n = '0' and (undefined(addr) or undefined(we_n) or (we_n = '0' and undefined(bw_n))) then
                violate(0);
            end if;
            if ld_n /= '0' then
                violate(1);
            end if;
            if ce_n = '0' and we_n = '0' and bw_n = "11" then
                violate(2);
            end if;
            if (dq_oe = '1' and not wv(0)) or (wv(0) and dq_oe /= '1') then
                violate(3);
            end if;
            if dq_oe = '1' and drove then
                violate(4);
            end if;
            if drove and oe_n /= '0' then
                violate(5);
            end if;
            -- the write whose data this edge samples
            if wv(0) then
                v := word_at(wa(0));
                lo := v mod 256;
                hi := v / 256;
                if wb(0) mod 2 = 0 then
                    if undefined(dq_o(7 downto 0)) then
                        violate(0);
                    else
                        lo := to_integer(dq_o(7 downto 0));
                    end if;
                end if;
                if wb(0) / 2 = 0 then
                    if undefined(dq_o(15 downto 8)) then
                        violate(0);
                    else
                        hi := to_integer(dq_o(15 downto 8));
                    end if;
                end if;
                mem(wa(0)) := hi * 256 + lo;
                written(wa(0)) := true;
            end if;
            -- the access registered at this edge
            if ce_n = '0' and not undefined(addr) and not undefined(we_n) then
                if we_n = '0' then
                    wv(RL) := true;
                    wa(RL) := to_integer(addr);
                    if undefined(bw_n) then
                        wb(RL) := 0;
                    else
                        wb(RL) := to_integer(bw_n);
                    end if;
                    n_writes := n_writes + 1;
                    writes <= to_unsigned(n_writes, 32);
                else
                    rv(RL - 1) := true;
                    ra(RL - 1) := to_integer(addr);
                    n_reads := n_reads + 1;
                    reads <= to_unsigned(n_reads, 32);
                end if;
            end if;
            -- the read data the part drives in the cycle after this edge
            if rv(0) then
                dq_i <= to_unsigned(word_at(ra(0)), 16);
                drove := true;
            else
                dq_i <= (others => 'Z');
                drove := false;
            end if;
            if dump_stb /= ack then
                file_open(f, "sram_dump.txt", write_mode);
                a := to_integer(dump_addr);
                for i in 0 to to_integer(dump_len) - 1 loop
                    write(l, word_at((a + i) mod 2**20));
                    writeline(f, l);
                end loop;
                file_close(f);
                ack := dump_stb;
                dump_ack <= ack;
            end if;
        end if;
    end process;
end architecture model;
"""

#: The test models' sources by language: file name -> text (written beside the converted top).
MODELS = {"vhdl": {"camera_player.vhd": CAMERA_PLAYER_VHDL, "sram_part.vhd": SRAM_PART_VHDL},
          "verilog": {"camera_player.v": CAMERA_PLAYER_V, "sram_part.v": SRAM_PART_V}}


def _driven(*sigs) -> None:
    for s in sigs:
        s.driven = "wire"


@block
def camera_player(base, go, pclk, vsync, href, data, done, samples, *, file_name: str, vsync_active: int,
                  href_active: int, label: str):
    """One camera player (module docstring) as user-defined code: an instance of the hand-written model."""
    _driven(pclk, vsync, href, data, done, samples)
    base.read = go.read = True

    @always(base.negedge)
    def model():  # the HDL model is the user code below; MyHDL's own simulation of the harness is not used
        pass

    return model


camera_player.verilog_code = (
    'camera_player #(.FILE("$file_name"), .VSYNC_ACTIVE($vsync_active), .HREF_ACTIVE($href_active)) $label '
    '(.base($base), .go($go), .pclk($pclk), .vsync($vsync), .href($href), .data($data), .done($done), '
    '.samples($samples));')
camera_player.vhdl_code = (
    '$label: entity work.camera_player generic map (FILE_NAME => "$file_name", VSYNC_ACTIVE => $vsync_active, '
    'HREF_ACTIVE => $href_active) port map (base => $base, go => $go, pclk => $pclk, vsync => $vsync, href => $href, '
    'data => $data, done => $done, samples => $samples);')


@block
def sram_part(clk, addr, ce_n, ld_n, we_n, bw_n, oe_n, dq_o, dq_oe, dq_i, dump_stb, dump_addr, dump_len, dump_ack,
              viol_count, viol_rule, viol_edge, viol_rules, reads, writes, *, read_latency: int):
    """The SRAM part (module docstring) as user-defined code: an instance of the hand-written model."""
    _driven(dq_i, dump_ack, viol_count, viol_rule, viol_edge, viol_rules, reads, writes)
    for s in (clk, addr, ce_n, ld_n, we_n, bw_n, oe_n, dq_o, dq_oe, dump_stb, dump_addr, dump_len):
        s.read = True

    @always(clk.posedge)
    def model():  # the HDL model is the user code below
        pass

    return model


_SRAM_PORTS = ("clk", "addr", "ce_n", "ld_n", "we_n", "bw_n", "oe_n", "dq_o", "dq_oe", "dq_i", "dump_stb",
               "dump_addr", "dump_len", "dump_ack", "viol_count", "viol_rule", "viol_edge", "viol_rules", "reads",
               "writes")
sram_part.verilog_code = ("sram_part #(.RL($read_latency)) u_sram_part (" +
                          ", ".join(f".{p}(${p})" for p in _SRAM_PORTS) + ");")
sram_part.vhdl_code = ("u_sram_part: entity work.sram_part generic map (RL => $read_latency) port map (" +
                       ", ".join(f"{p} => ${p}" for p in _SRAM_PORTS) + ");")


def camera_fifos(top) -> list:
    """The two camera FIFOs (async_fifo instances inside camera_pair) of an elaborated stereo_frontend ``top``."""
    found = []

    def walk(b, inside):
        for s in getattr(b, "subs", ()):
            name = getattr(s, "name", "")
            if inside and name.startswith("camera_interface"):
                found.extend(c for c in s.subs if getattr(c, "name", "").startswith("async_fifo"))
            walk(s, inside or name.startswith("camera_pair"))

    walk(top, False)
    if len(found) != 2:
        raise ValueError(f"frontend_harness: expected the two camera FIFOs inside camera_pair, found {len(found)}")
    return found


@block
def fifo_watch(wclk, wbin, rgray, clear, level_max):
    """The highest fill of an async_fifo seen from its write side (its write pointer against the synchronised
    read pointer, what its ``full`` flag compares) since the last toggle of ``clear``: a coverage probe of the
    fast harness (test logic, not an FPGA block)."""
    bits = len(wbin)
    rbin = Signal(intbv(0)[bits:])
    fill = Signal(intbv(0)[bits:])
    seen = Signal(bool(0))

    @always_comb
    def decode():
        v = intbv(0)[bits:]
        v[:] = rgray
        for j in range(1, bits):  # binary = the Gray code xor all its right shifts
            v[:] = v ^ (rgray >> j)
        rbin.next = v

    mod = 1 << bits

    @always_comb
    def level():
        d = intbv(0, min=-mod, max=mod)
        d[:] = wbin - rbin
        if d < 0:
            d[:] = d + mod
        fill.next = d[bits:]

    @always(wclk.posedge)
    def track():
        if clear != seen:
            seen.next = clear
            level_max.next = fill
        elif fill > level_max:
            level_max.next = fill

    return decode, level, track


class HarnessPorts:
    """The test models' ports of the harness (fresh signals): each camera's ``done`` and ``samples``, the SRAM
    part's backdoor and rule counters (module docstring)."""

    def __init__(self):
        self.cam_go = Signal(bool(0))
        self.fifo_clear = Signal(bool(0))
        self.cam_l_fifo_max, self.cam_r_fifo_max = Signal(intbv(0)[8:]), Signal(intbv(0)[8:])
        self.cam_l_done, self.cam_r_done = Signal(bool(0)), Signal(bool(0))
        self.cam_l_samples, self.cam_r_samples = Signal(intbv(0)[32:]), Signal(intbv(0)[32:])
        self.sram_dump_stb, self.sram_dump_ack = Signal(bool(0)), Signal(bool(0))
        self.sram_dump_addr, self.sram_dump_len = Signal(intbv(0)[20:]), Signal(intbv(0)[21:])
        self.sram_viol_count, self.sram_viol_edge = Signal(intbv(0)[32:]), Signal(intbv(0)[32:])
        self.sram_viol_rule, self.sram_viol_rules = Signal(intbv(0)[4:]), Signal(intbv(0)[8:])
        self.sram_reads, self.sram_writes = Signal(intbv(0)[32:]), Signal(intbv(0)[32:])


_TM_PORTS = ("cam_go", "fifo_clear", "cam_l_fifo_max", "cam_r_fifo_max", "cam_l_done", "cam_l_samples", "cam_r_done",
             "cam_r_samples", "sram_dump_stb", "sram_dump_addr",
             "sram_dump_len", "sram_dump_ack", "sram_viol_count", "sram_viol_rule", "sram_viol_edge",
             "sram_viol_rules", "sram_reads", "sram_writes")


@block
def frontend_harness(clk, rst, hclk, hrst, base_l, wrst_l, base_r, wrst_r, bus, cam_go, fifo_clear, cam_l_fifo_max,
                     cam_r_fifo_max, cam_l_done, cam_l_samples,
                     cam_r_done, cam_r_samples, sram_dump_stb, sram_dump_addr, sram_dump_len, sram_dump_ack,
                     sram_viol_count, sram_viol_rule, sram_viol_edge, sram_viol_rules, sram_reads, sram_writes,
                     **params):
    """stereo_frontend (``params``) with two camera players and the SRAM part (module docstring)."""
    from eyestereo.tools.camera import CameraTiming

    if params.get("memory", "sram") != "sram" or params.get("kind", "nobl") != "nobl":
        raise ValueError("frontend_harness: its SRAM part is a NoBL SRAM: memory='sram', kind='nobl' only, got "
                         f"memory={params.get('memory', 'sram')!r}, kind={params.get('kind', 'nobl')!r}")
    rl = params.get("read_latency", 2)
    if not 1 <= rl <= 3:
        raise ValueError(f"frontend_harness: the SRAM part's read latency must be 1..3, got {rl}")
    t = CameraTiming()
    cam_l, cam_r, sram = CameraBus(), CameraBus(), SramPins()
    top = stereo_frontend(clk, rst, hclk, hrst, cam_l, wrst_l, cam_r, wrst_r, bus, sram, **params)
    players = [camera_player(base, cam_go, cam.pclk, cam.vsync, cam.href, cam.data, done, samples,
                             file_name=SCRIPT_FILES[side], vsync_active=t.vsync_active, href_active=t.href_active,
                             label=f"u_camera_player_{side}")
               for side, base, cam, done, samples in (("l", base_l, cam_l, cam_l_done, cam_l_samples),
                                                     ("r", base_r, cam_r, cam_r_done, cam_r_samples))]
    part = sram_part(clk, sram.addr, sram.ce_n, sram.ld_n, sram.we_n, sram.bw_n, sram.oe_n, sram.dq_o, sram.dq_oe,
                     sram.dq_i, sram_dump_stb, sram_dump_addr, sram_dump_len, sram_dump_ack, sram_viol_count,
                     sram_viol_rule, sram_viol_edge, sram_viol_rules, sram_reads, sram_writes, read_latency=rl)
    watches = [fifo_watch(f.sigdict["wclk"], f.sigdict["wbin"], f.sigdict["rgray_s2"], fifo_clear, level)
               for f, level in zip(camera_fifos(top), (cam_l_fifo_max, cam_r_fifo_max))]
    return top, players, part, watches


def _build(p):
    tm = HarnessPorts()
    ports = dict(clk=Signal(bool(0)), rst=ResetSignal(0, active=1, isasync=False), hclk=Signal(bool(0)),
                 hrst=ResetSignal(0, active=1, isasync=False), base_l=Signal(bool(0)),
                 wrst_l=ResetSignal(0, active=1, isasync=False), base_r=Signal(bool(0)),
                 wrst_r=ResetSignal(0, active=1, isasync=False), bus=AxiLite(REGMAP.addr_bits))
    ports.update({n: getattr(tm, n) for n in _TM_PORTS})
    return ports


_DEFAULTS = block_defaults(stereo_frontend)
BENCH_TOPS[NAME] = BlockSpec(
    NAME, "bench top: stereo_frontend with HDL camera players and the HDL SRAM part", frontend_harness,
    dict(_DEFAULTS), sink_width=lambda p: 8, source_width=lambda p: 16, hw_params=tuple(_DEFAULTS),
    build=_build, clocks=(("clk", 100.0), ("hclk", 50.0)), sources=lambda lang: MODELS[lang])


@block
def sram_part_tb(clk, addr, ce_n, ld_n, we_n, bw_n, oe_n, dq_o, dq_oe, dq_i, dump_stb, dump_addr, dump_len, dump_ack,
                 viol_count, viol_rule, viol_edge, viol_rules, reads, writes, *, read_latency: int = 2):
    """The SRAM part alone, its pins the top's ports: the bench top of its cross-check against
    :class:`~eyestereo.tools.sram.SramChip` (:mod:`eyestereo.sim.benches.tb_sram_part`)."""
    if not 1 <= read_latency <= 3:
        raise ValueError(f"sram_part_tb: the SRAM part's read latency must be 1..3, got {read_latency}")
    return sram_part(clk, addr, ce_n, ld_n, we_n, bw_n, oe_n, dq_o, dq_oe, dq_i, dump_stb, dump_addr, dump_len,
                     dump_ack, viol_count, viol_rule, viol_edge, viol_rules, reads, writes, read_latency=read_latency)


def _build_part(p):
    pins = SramPins()
    tm = HarnessPorts()
    return dict(clk=Signal(bool(0)), addr=pins.addr, ce_n=pins.ce_n, ld_n=pins.ld_n, we_n=pins.we_n, bw_n=pins.bw_n,
                oe_n=pins.oe_n, dq_o=pins.dq_o, dq_oe=pins.dq_oe, dq_i=pins.dq_i, dump_stb=tm.sram_dump_stb,
                dump_addr=tm.sram_dump_addr, dump_len=tm.sram_dump_len, dump_ack=tm.sram_dump_ack,
                viol_count=tm.sram_viol_count, viol_rule=tm.sram_viol_rule, viol_edge=tm.sram_viol_edge,
                viol_rules=tm.sram_viol_rules, reads=tm.sram_reads, writes=tm.sram_writes)


BENCH_TOPS["sram_part_tb"] = BlockSpec(
    "sram_part_tb", "bench top: the HDL SRAM part alone (its cross-check against the Python SramChip)", sram_part_tb,
    dict(read_latency=2), sink_width=lambda p: 16, source_width=lambda p: 16, hw_params=("read_latency",),
    build=_build_part, clocks=(("clk", 100.0),), sources=lambda lang: {k: v for k, v in MODELS[lang].items()
                                                                       if k.startswith("sram_part")})
