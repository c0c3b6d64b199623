#!/usr/bin/env bash
# Installs what the build needs when it is missing; fast no-op when present.
#   tools/setup.sh build   the wasm32 target and wasm-bindgen-cli (exact Cargo.lock version)
#   tools/setup.sh e2e     Debian's chromium and ffmpeg and playwright-core (for the browser tests;
#                          the video suite encodes its WebM and mp4v test files with ffmpeg)
#   tools/setup.sh node    the TypeScript compiler of the node tier (tests/node, pinned)
set -euo pipefail
cd "$(dirname "$0")/.."

need_build() {
  if ! rustup target list --installed | grep -qx wasm32-unknown-unknown; then
    echo "setup: adding the wasm32-unknown-unknown target"
    rustup target add wasm32-unknown-unknown
  fi
  local want
  want=$(awk '/^name = "wasm-bindgen"$/ {getline; gsub(/version = |"/, ""); print; exit}' Cargo.lock)
  if [ -z "$want" ]; then
    echo "setup: cannot read the wasm-bindgen version from Cargo.lock" >&2
    exit 1
  fi
  local have=""
  if command -v wasm-bindgen >/dev/null 2>&1; then
    have=$(wasm-bindgen --version | awk '{print $2}')
  fi
  if [ "$have" != "$want" ]; then
    echo "setup: installing wasm-bindgen-cli $want (found '${have:-none}'; takes a few minutes once)"
    cargo install wasm-bindgen-cli --version "$want"
  fi
}

need_e2e() {
  if [ ! -x /usr/bin/chromium ]; then
    echo "setup: installing Debian's chromium"
    local sudo=""
    [ "$(id -u)" -ne 0 ] && sudo="sudo"
    $sudo apt-get install -y chromium || { $sudo apt-get update && $sudo apt-get install -y chromium; }
  fi
  if [ ! -x /usr/bin/ffmpeg ]; then
    echo "setup: installing Debian's ffmpeg (the video suite makes its test videos with it)"
    local sudo=""
    [ "$(id -u)" -ne 0 ] && sudo="sudo"
    $sudo apt-get install -y ffmpeg || { $sudo apt-get update && $sudo apt-get install -y ffmpeg; }
  fi
  if [ ! -d tests/e2e/node_modules/playwright-core ]; then
    echo "setup: installing playwright-core for the browser tests"
    (cd tests/e2e && npm install --no-audit --no-fund)
  fi
}

need_node() {
  if [ ! -f tests/node/node_modules/typescript/package.json ]; then
    echo "setup: installing typescript for the node tier's type checks"
    (cd tests/node && npm install --no-audit --no-fund)
  fi
}

case "${1:-build}" in
  build) need_build ;;
  e2e) need_e2e ;;
  node) need_node ;;
  *) echo "usage: tools/setup.sh build|e2e|node" >&2; exit 2 ;;
esac
