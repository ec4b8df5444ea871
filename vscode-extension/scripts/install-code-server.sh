#!/usr/bin/env bash
# Installs code-server (the real VS Code, served to a browser) into $1 for the
# end-to-end test. Needs Debian's libkrb5-dev (a native module) and ripgrep.
# @vscode/ripgrep's postinstall downloads rg from the internet unless its
# cache (os.tmpdir()/vscode-ripgrep-cache-VERSION/ripgrep-vTAG-TARGET.tar.gz)
# already holds the archive: we put Debian's rg there.
set -euo pipefail
prefix="$1"
version="${CODE_SERVER_VERSION:-4.100.3}"
if [ -x "$prefix/node_modules/.bin/code-server" ] && \
   [ -d "$prefix/node_modules/code-server/lib/vscode/node_modules" ] && \
   grep -q "\"version\": \"$version\"" "$prefix/node_modules/code-server/package.json"; then
  echo "code-server $version already in $prefix"
  exit 0
fi
rg_bin="$(command -v rg)"
tmp="${TMPDIR:-/tmp}"
# The versions code-server 4.100.3 pins (lib/vscode/npm-shrinkwrap.json).
for pair in "1.15.11 v13.0.0-10"; do
  set -- $pair
  cache="$tmp/vscode-ripgrep-cache-$1"
  mkdir -p "$cache"
  stage="$(mktemp -d)"
  cp "$rg_bin" "$stage/rg"
  tar czf "$cache/ripgrep-$2-x86_64-unknown-linux-musl.tar.gz" -C "$stage" rg
  rm -rf "$stage"
done
mkdir -p "$prefix"
# Root needs unsafe-perm for the postinstall (which runs `npm install` in
# lib/vscode, native modules included); npm 11 runs install scripts only
# when allowed, and the nested installs read the same variable.
export npm_config_unsafe_perm=true npm_config_yes=true
export npm_config_dangerously_allow_all_scripts=true
npm install --prefix "$prefix" --no-audit --no-fund "code-server@$version"
