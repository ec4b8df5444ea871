#!/usr/bin/env bash
# The platform .vsix: the extension with the release `semo` inside it
# (server/semo, where src/pure/discovery.ts looks first), so that installing
# the extension is all a VS Code user does.
#
#   scripts/package-platform.sh [SEMO_BIN]   # default: ../target/release/semo
#
# Writes semo-<target>.vsix (target: $VSCE_TARGET, default linux-x64).
set -euo pipefail
ext="$(cd "$(dirname "$0")/.." && pwd)"
repo="$(cd "$ext/.." && pwd)"
semo="${1:-${SEMO_BIN:-$repo/target/release/semo}}"
target="${VSCE_TARGET:-linux-x64}"
[ -x "$semo" ] || { echo "package: $semo is missing: run cargo build --release first" >&2; exit 1; }
cd "$ext"
[ -d node_modules ] || npm ci --no-audit --no-fund
npm run build
rm -rf server
mkdir server
trap 'rm -rf "$ext/server"' EXIT
cp "$semo" server/semo
npx vsce package --no-dependencies --allow-missing-repository --skip-license \
  --target "$target" -o "semo-$target.vsix"
echo "package: semo-$target.vsix ($(du -h "semo-$target.vsix" | cut -f1), server $(du -h server/semo | cut -f1))"
