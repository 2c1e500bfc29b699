// axi_rw_shim.h: DutCore for a Verilated streaming top V with an AXI4 manager port that both reads
// (m_axi_ar*, m_axi_r*) and writes (m_axi_aw*, m_axi_w*, m_axi_b*), answered cycle by cycle by
// both ports of one AxiMem (tb/axi_mem.h) over one image: what gicube_cache's write-back needs
// (reads of lines, write-backs of dirty ones). AxiShim's class (tb/axi_shim.h) with `Write`.
#pragma once

#include "axi_mem.h"
#include "axi_ports.h"
#include "axi_shim.h"

namespace cube5 {

template <class V>
using AxiRwShim = AxiManagerShim<V, true>;

}  // namespace cube5
