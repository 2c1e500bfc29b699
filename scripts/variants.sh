#!/usr/bin/env bash
# Lists every verified RTL configuration, one per line: TOP NAME FLAGS FILES [Param=value ...]
# (FLAGS comma-joined or `-`; FILES comma-joined, packages first, `-f` includes expanded). The
# reader is scripts/cube5-gen, the same code tb-rs/build.rs uses: rtl/**/<top>.variants and
# <top>.f are parsed in one place only.
set -euo pipefail
cd "$(dirname "$0")/.."
CARGO_TARGET_DIR=target/cube5-gen cargo build -q -p cube5-gen
target/cube5-gen/debug/cube5-gen variants
