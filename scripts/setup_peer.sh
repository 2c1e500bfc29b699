#!/usr/bin/env bash
# Makes .venv-peer for the peer benchmark (scripts/bench_peer.py, `make bench-peer`): VTK and numpy
# from PyPI at pinned versions, then checks that VTK renders offscreen. Without an X display the
# VTK wheel renders through EGL; when that fails on Debian, this installs Mesa's EGL and software
# OpenGL (libegl1 libegl-mesa0 libgl1-mesa-dri) with apt-get (sudo when not root) and tries again.
#   PEER_VTK    VTK version (default 9.7.1), PEER_NUMPY numpy version (default 2.4.6)
set -euo pipefail
cd "$(dirname "$0")/.."
venv=.venv-peer
vtk=${PEER_VTK:-9.7.1}
numpy=${PEER_NUMPY:-2.4.6}
fail() { echo "bench-peer: $*" >&2; exit 1; }

python=$(command -v python3.11 || command -v python3) || fail "no python3 (apt-get install python3 python3-venv)"
if [ ! -x "$venv/bin/python" ]; then
  echo "bench-peer: making $venv"
  "$python" -m venv "$venv" || fail "cannot make $venv (apt-get install python3-venv)"
fi
have=$("$venv/bin/python" -c 'import vtk, numpy; print(vtk.vtkVersion.GetVTKVersion(), numpy.__version__)' 2>/dev/null || true)
if [ "$have" != "$vtk $numpy" ]; then
  echo "bench-peer: installing vtk==$vtk numpy==$numpy from PyPI into $venv"
  "$venv/bin/pip" install -q --disable-pip-version-check "vtk==$vtk" "numpy==$numpy" \
    || fail "cannot install vtk==$vtk numpy==$numpy from PyPI into $venv (see pip's message above)"
fi

smoke() { "$venv/bin/python" scripts/bench_peer.py --smoke-test 2>/dev/null; }
if ! smoke; then
  if command -v apt-get >/dev/null 2>&1; then
    sudo=""
    [ "$(id -u)" -eq 0 ] || sudo="sudo"
    echo "bench-peer: VTK cannot render offscreen; installing Mesa EGL (libegl1 libegl-mesa0 libgl1-mesa-dri) with apt-get"
    $sudo apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends \
      libegl1 libegl-mesa0 libgl1-mesa-dri >/dev/null
  fi
  smoke || { "$venv/bin/python" scripts/bench_peer.py --smoke-test || true; \
    fail "VTK $vtk cannot render offscreen here (needs EGL or OSMesa: libegl1 libegl-mesa0 libgl1-mesa-dri)"; }
fi
