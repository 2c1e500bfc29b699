#!/usr/bin/env bash
# Lists every verified RTL configuration from rtl/**/<top>.variants (the single source that
# tb-rs/build.rs reads too), one per line: TOP FILELIST NAME FLAGS [Param=value ...]
# FLAGS is the comma-joined list of words without `=` (gate, fmax), or `-`.
set -euo pipefail
cd "$(dirname "$0")/.."
find rtl -name '*.variants' | sort | while read -r vfile; do
  top=$(basename "$vfile" .variants)
  flist="${vfile%.variants}.f"
  sed -e 's/#.*//' "$vfile" | while read -r name rest; do
    [ -n "$name" ] || continue
    params=$(echo "$rest" | tr ' ' '\n' | grep '=' | tr '\n' ' ' || true)
    flags=$(echo "$rest" | tr ' ' '\n' | grep -v '=' | grep . | paste -sd, - || true)
    echo "$top $flist $name ${flags:--} $params"
  done
done
