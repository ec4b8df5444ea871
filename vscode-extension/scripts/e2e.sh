#!/usr/bin/env bash
# The extension in the real VS Code: packages the .vsix, installs code-server
# (once, under target/), installs the .vsix into a fresh profile, serves a
# copy of test/e2e/workspace and drives it with headless Chromium
# (test/e2e/). The .vsix is the platform one with the release build inside
# (scripts/package-platform.sh): build it first with `cargo build --release`
# (or set SEMO_BIN). No `semo.server.path` and no `semo` on code-server's
# PATH, so the extension runs the server it bundles, as a user's would.
#
# Needs Debian's chromium, ripgrep, libkrb5-dev, mosquitto and mosquitto-clients (see .ci/run).
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
bash scripts/package-platform.sh "$semo"
vsix="$ext/semo-linux-x64.vsix"
cs_prefix="${CODE_SERVER_PREFIX:-$work/code-server}"
bash scripts/install-code-server.sh "$cs_prefix"
code_server="$cs_prefix/node_modules/.bin/code-server"
echo "e2e: setup took $(( $(date +%s) - started ))s"

# A private MQTT broker for the Robots (live) test, on a free loopback port
# (Debian's mosquitto, see .ci/run); the test publishes robot statuses to it.
mosquitto_bin="$(command -v mosquitto || echo /usr/sbin/mosquitto)"
[ -x "$mosquitto_bin" ] || { echo "e2e: mosquitto is missing (apt-get install mosquitto mosquitto-clients)" >&2; exit 1; }
mqtt_port="$(python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')"
mkdir -p "$work"
printf 'user %s\nlistener %s 127.0.0.1\nallow_anonymous true\nset_tcp_nodelay true\n' "$(id -un)" "$mqtt_port" > "$work/mosquitto.conf"
"$mosquitto_bin" -c "$work/mosquitto.conf" > "$work/mosquitto.log" 2>&1 &
broker_pid=$!
trap 'kill "$broker_pid" 2>/dev/null || true' EXIT

# A fresh profile and extensions folder each run; the workspace is a copy,
# since the test writes into it.
rm -rf "$work/profile" "$work/extensions" "$work/workspace" "$work/shots"
mkdir -p "$work/profile/User" "$work/extensions" "$work/shots"
cp -r "$ext/test/e2e/workspace" "$work/workspace"
cat > "$work/profile/User/settings.json" <<JSON
{
  "[semo]": { "editor.formatOnSave": true },
  "semo.trace.server": "messages",
  "semo.monitor.broker": "mqtt://127.0.0.1:$mqtt_port",
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
"$code_server" "${common[@]}" --install-extension "$vsix"

# code-server's PATH without any folder holding a `semo`.
clean_path=""
IFS=: read -ra dirs <<< "$PATH"
for d in "${dirs[@]}"; do
  [ -e "$d/semo" ] || clean_path="${clean_path:+$clean_path:}$d"
done
if PATH="$clean_path" command -v semo > /dev/null; then
  echo "e2e: semo is still on the PATH" >&2; exit 1
fi

PATH="$clean_path" "$code_server" "${common[@]}" --auth none --bind-addr "127.0.0.1:$port" \
  --disable-telemetry --disable-update-check --disable-workspace-trust \
  --disable-getting-started-override "$work/workspace" > "$work/code-server.log" 2>&1 &
server_pid=$!
trap 'kill "$server_pid" "$broker_pid" 2>/dev/null || true; wait "$server_pid" 2>/dev/null || true' EXIT
for _ in $(seq 1 120); do
  if curl -fsS "http://127.0.0.1:$port/healthz" > /dev/null 2>&1; then break; fi
  if ! kill -0 "$server_pid" 2>/dev/null; then
    echo "e2e: code-server exited:" >&2; cat "$work/code-server.log" >&2; exit 1
  fi
  sleep 0.5
done

CHROMIUM="$chromium" SEMO_E2E_URL="http://127.0.0.1:$port/?folder=$work/workspace" \
  SEMO_E2E_OUT="$work" SEMO_E2E_WORKSPACE="$work/workspace" SEMO_E2E_MQTT_PORT="$mqtt_port" \
  node --test --test-timeout=240000 "$ext/test/e2e/"
echo "e2e: done in $(( $(date +%s) - started ))s; screenshots in $work/shots"
