#!/usr/bin/env bash
# verilator --lint-only -Wall (with assertions elaborated) on every top at every verified
# configuration, one Verilator per core (LINT_JOBS overrides). Waivers live only in
# rtl/lint/verilator.vlt. `-Irtl`: the include folder (cube5_gen::variants::INCLUDE_DIR, where
# cube5_axi_ports.svh is).
set -euo pipefail
cd "$(dirname "$0")/.."
failed=$(mktemp)
trap 'rm -f "$failed"' EXIT
# lint_one TOP NAME FLAGS FILES PARAMS...: one configuration; a failure is named in $failed.
lint_one() {
  local top=$1 name=$2 files=$4
  shift 4
  local gflags=() p
  for p in "$@"; do gflags+=("-G$p"); done
  if ! verilator --lint-only -Wall --assert -Irtl rtl/lint/verilator.vlt --top-module "$top" "${gflags[@]}" ${files//,/ }; then
    echo "lint FAILED: $top $name ($*)" | tee -a "$failed"
  fi
}
jobs=${LINT_JOBS:-$(nproc)}
count=0
running=0
while read -r line; do
  if [ "$running" -ge "$jobs" ]; then
    wait -n || true
    running=$((running - 1))
  fi
  # shellcheck disable=SC2086
  lint_one $line &
  running=$((running + 1))
  count=$((count + 1))
done < <(scripts/variants.sh)
wait
[ "$count" -gt 0 ] || { echo "lint: no configurations read (scripts/variants.sh failed?)"; exit 1; }
if [ -s "$failed" ]; then exit 1; fi
echo "lint clean: $count configurations (verilator $(verilator --version | cut -d' ' -f2) -Wall)"
