#!/usr/bin/env bash
# The extension in the real VS Code: packages the .vsix, installs code-server
# (once, under target/), installs the .vsix into a fresh profile, serves a
# copy of test/e2e/workspace and drives it with headless Chromium
# (test/e2e/run.mjs). The server is the release build: build it first with
# `cargo build --release` (or set SEMO_BIN).
#
# Needs Debian's chromium, ripgrep and libkrb5-dev (see .ci/run).
# Artifacts (screenshots, code-server's log) land in target/vscode-e2e/.
set -euo pipefail
ext="$(cd "$(dirname "$0")/.." && pwd)"
repo="$(cd "$ext/.." && pwd)"
work="$repo/target/vscode-e2e"
semo="${SEMO_BIN:-$repo/target/release/semo}"
chromium="${CHROMIUM:-$(command -v chromium || true)}"
port="${SEMO_E2E_PORT:-18080}"

[ -x "$semo" ] || { echo "e2e: $semo is missing: run cargo build --release first" >&2; exit 1; }
[ -n "$chromium" ] || { echo "e2e: chromium is missing (apt-get install chromium)" >&2; exit 1; }

started=$(date +%s)
cd "$ext"
[ -d node_modules ] || npm ci --no-audit --no-fund
npm run package
cs_prefix="${CODE_SERVER_PREFIX:-$work/code-server}"
bash scripts/install-code-server.sh "$cs_prefix"
code_server="$cs_prefix/node_modules/.bin/code-server"
echo "e2e: setup took $(( $(date +%s) - started ))s"

# A fresh profile and extensions folder each run; the workspace is a copy,
# since the test writes into it.
rm -rf "$work/profile" "$work/extensions" "$work/workspace" "$work/shots"
mkdir -p "$work/profile/User" "$work/extensions" "$work/shots"
cp -r "$ext/test/e2e/workspace" "$work/workspace"
cat > "$work/profile/User/settings.json" <<JSON
{
  "semo.server.path": "$semo",
  "semo.trace.server": "messages",
  "workbench.startupEditor": "none",
  "workbench.tips.enabled": false,
  "workbench.enableExperiments": false,
  "workbench.welcomePage.walkthroughs.openOnInstall": false,
  "security.workspace.trust.enabled": false,
  "extensions.autoCheckUpdates": false,
  "extensions.autoUpdate": false,
  "telemetry.telemetryLevel": "off",
  "update.mode": "none",
  "chat.disableAIFeatures": true,
  "window.commandCenter": false,
  "git.openRepositoryInParentFolders": "never"
}
JSON
: > "$work/code-server.yaml"
common=(--config "$work/code-server.yaml" --user-data-dir "$work/profile" --extensions-dir "$work/extensions")
"$code_server" "${common[@]}" --install-extension "$ext/semo.vsix"

"$code_server" "${common[@]}" --auth none --bind-addr "127.0.0.1:$port" \
  --disable-telemetry --disable-update-check --disable-workspace-trust \
  --disable-getting-started-override "$work/workspace" > "$work/code-server.log" 2>&1 &
server_pid=$!
trap 'kill "$server_pid" 2>/dev/null || true; wait "$server_pid" 2>/dev/null || true' EXIT
for _ in $(seq 1 120); do
  if curl -fsS "http://127.0.0.1:$port/healthz" > /dev/null 2>&1; then break; fi
  if ! kill -0 "$server_pid" 2>/dev/null; then
    echo "e2e: code-server exited:" >&2; cat "$work/code-server.log" >&2; exit 1
  fi
  sleep 0.5
done

CHROMIUM="$chromium" SEMO_E2E_URL="http://127.0.0.1:$port/?folder=$work/workspace" \
  SEMO_E2E_OUT="$work" SEMO_E2E_WORKSPACE="$work/workspace" \
  node --test --test-timeout=240000 "$ext/test/e2e/"
echo "e2e: done in $(( $(date +%s) - started ))s; screenshots in $work/shots"
