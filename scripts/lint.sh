#!/usr/bin/env bash
# verilator --lint-only -Wall (with assertions elaborated) on every top at every verified
# configuration. Waivers live only in rtl/lint/verilator.vlt. `-Irtl`: the include folder
# (cube5_gen::variants::INCLUDE_DIR, where cube5_axi_ports.svh is).
set -euo pipefail
cd "$(dirname "$0")/.."
fail=0
count=0
while read -r top name flags files params; do
  gflags=()
  for p in $params; do gflags+=("-G$p"); done
  if ! verilator --lint-only -Wall --assert -Irtl rtl/lint/verilator.vlt --top-module "$top" "${gflags[@]}" ${files//,/ }; then
    echo "lint FAILED: $top $name ($params)"
    fail=1
  fi
  count=$((count + 1))
done < <(scripts/variants.sh)
[ "$count" -gt 0 ] || { echo "lint: no configurations read (scripts/variants.sh failed?)"; exit 1; }
if [ "$fail" -ne 0 ]; then exit 1; fi
echo "lint clean: $count configurations (verilator $(verilator --version | cut -d' ' -f2) -Wall)"
