// cube5_axi_ports.svh: the AXI4 manager and AXI4-Lite subordinate port lists, written once
// (issue 16). A module with an AXI port includes this file and names the channels it has:
//
//   `include "cube5_axi_ports.svh"
//   module cube5_axi_rd #(...) (
//     input  logic clk_i,
//     ...
//     `CUBE5_AXI4_RD_MGR_PORTS(m_axi_, AddrW, DataW, IdW)
//   );
//
// Each macro expands to flat ports with the standard AXI signal names behind the prefix and the
// direction suffix (`m_axi_araddr_o`, `s_axil_wready_o`), so a top stays drop-in for FPGA tools
// and the test-bench shims (tb/axi_ports.h) keep their names. No trailing comma: the module puts
// one after the macro when more ports follow. Every tool reads the file from `rtl/` (Verilator
// `-I`, Yosys `read_verilog -I`; scripts/cube5-gen passes it, and each filelist that needs it
// names it first, so a change to it rebuilds those tops; docs/adding-a-unit.md).
//
// Manager read channels, CUBE5_AXI4_RD_MGR_PORTS(PFX, ADDR_W, DATA_W, ID_W):
//   AR: araddr (ADDR_W, burst start), arlen (8, beats - 1), arsize (3, log2 bytes per beat),
//       arburst (2, INCR), arid (ID_W), arvalid, arready (input);
//   R:  rdata (DATA_W), rresp (2), rlast, rid (ID_W), rvalid (inputs), rready.
// Manager write channels, CUBE5_AXI4_WR_MGR_PORTS(PFX, ADDR_W, DATA_W, ID_W):
//   AW: awaddr, awlen, awsize, awburst, awid, awvalid, awready (input), as AR;
//   W:  wdata (DATA_W), wstrb (DATA_W / 8), wlast, wvalid, wready (input);
//   B:  bresp (2), bid (ID_W), bvalid (inputs), bready.
// Both directions, CUBE5_AXI4_MGR_PORTS(PFX, ADDR_W, DATA_W, ID_W): the read, then the write.
// Subordinate AXI4-Lite, CUBE5_AXIL_SUB_PORTS(PFX, ADDR_W): 32-bit data, no AxPROT (a block that
// takes it declares `awprot_i` / `arprot_i` itself);
//   AW: awvalid, awready, awaddr (ADDR_W); W: wvalid, wready, wdata (32), wstrb (4);
//   B:  bvalid, bready, bresp (2); AR: arvalid, arready, araddr (ADDR_W);
//   R:  rvalid, rready, rdata (32), rresp (2).
`ifndef CUBE5_AXI_PORTS_SVH
`define CUBE5_AXI_PORTS_SVH

`define CUBE5_AXI4_RD_MGR_PORTS(PFX, ADDR_W, DATA_W, ID_W) \
  output logic [(ADDR_W)-1:0]   PFX``araddr_o, \
  output logic [7:0]            PFX``arlen_o, \
  output logic [2:0]            PFX``arsize_o, \
  output logic [1:0]            PFX``arburst_o, \
  output logic [(ID_W)-1:0]     PFX``arid_o, \
  output logic                  PFX``arvalid_o, \
  input  logic                  PFX``arready_i, \
  input  logic [(DATA_W)-1:0]   PFX``rdata_i, \
  input  logic [1:0]            PFX``rresp_i, \
  input  logic                  PFX``rlast_i, \
  input  logic [(ID_W)-1:0]     PFX``rid_i, \
  input  logic                  PFX``rvalid_i, \
  output logic                  PFX``rready_o

`define CUBE5_AXI4_WR_MGR_PORTS(PFX, ADDR_W, DATA_W, ID_W) \
  output logic [(ADDR_W)-1:0]   PFX``awaddr_o, \
  output logic [7:0]            PFX``awlen_o, \
  output logic [2:0]            PFX``awsize_o, \
  output logic [1:0]            PFX``awburst_o, \
  output logic [(ID_W)-1:0]     PFX``awid_o, \
  output logic                  PFX``awvalid_o, \
  input  logic                  PFX``awready_i, \
  output logic [(DATA_W)-1:0]   PFX``wdata_o, \
  output logic [(DATA_W)/8-1:0] PFX``wstrb_o, \
  output logic                  PFX``wlast_o, \
  output logic                  PFX``wvalid_o, \
  input  logic                  PFX``wready_i, \
  input  logic [1:0]            PFX``bresp_i, \
  input  logic [(ID_W)-1:0]     PFX``bid_i, \
  input  logic                  PFX``bvalid_i, \
  output logic                  PFX``bready_o

`define CUBE5_AXI4_MGR_PORTS(PFX, ADDR_W, DATA_W, ID_W) \
  `CUBE5_AXI4_RD_MGR_PORTS(PFX, ADDR_W, DATA_W, ID_W), \
  `CUBE5_AXI4_WR_MGR_PORTS(PFX, ADDR_W, DATA_W, ID_W)

`define CUBE5_AXIL_SUB_PORTS(PFX, ADDR_W) \
  input  logic                  PFX``awvalid_i, \
  output logic                  PFX``awready_o, \
  input  logic [(ADDR_W)-1:0]   PFX``awaddr_i, \
  input  logic                  PFX``wvalid_i, \
  output logic                  PFX``wready_o, \
  input  logic [31:0]           PFX``wdata_i, \
  input  logic [3:0]            PFX``wstrb_i, \
  output logic                  PFX``bvalid_o, \
  input  logic                  PFX``bready_i, \
  output logic [1:0]            PFX``bresp_o, \
  input  logic                  PFX``arvalid_i, \
  output logic                  PFX``arready_o, \
  input  logic [(ADDR_W)-1:0]   PFX``araddr_i, \
  output logic                  PFX``rvalid_o, \
  input  logic                  PFX``rready_i, \
  output logic [31:0]           PFX``rdata_o, \
  output logic [1:0]            PFX``rresp_o

`endif
