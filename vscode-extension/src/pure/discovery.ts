// Where the `semo` binary is: the user's setting, then a binary shipped
// inside the extension, then `semo` on the PATH. Pure (the file system is
// passed in) so that it is tested without VS Code.

import * as path from 'path';

/** What discovery may look at; the real one wraps `fs` and `process`. */
export interface DiscoveryEnv {
  platform: NodeJS.Platform;
  /** The PATH variable. */
  pathVar: string;
  /** The extension's install folder. */
  extensionRoot: string;
  /** The first workspace folder, for a relative `semo.server.path`. */
  workspaceRoot?: string;
  /** The user's home folder, for `~/` in `semo.server.path`. */
  home?: string;
  /** Whether `file` exists and is a regular file that can be run. */
  isExecutable(file: string): boolean;
}

export type Found = {
  kind: 'found';
  command: string;
  /** `setting`, `bundled` or `path`: shown in the output channel. */
  source: 'setting' | 'bundled' | 'path';
};

export type NotFound = {
  kind: 'not-found';
  /** A message for the user: what was tried and how to fix it. */
  message: string;
  /** True when the setting names a file that is not there. */
  badSetting: boolean;
};

function exe(env: DiscoveryEnv, name: string): string {
  return env.platform === 'win32' ? `${name}.exe` : name;
}

/** The places inside the extension where a bundled server may sit. */
export function bundledCandidates(env: DiscoveryEnv): string[] {
  return [
    path.join(env.extensionRoot, 'server', exe(env, 'semo')),
    path.join(env.extensionRoot, 'bin', exe(env, 'semo')),
  ];
}

/** Expands `~/` and makes a relative setting relative to the workspace. */
export function resolveSetting(env: DiscoveryEnv, setting: string): string {
  let p = setting.trim();
  if ((p === '~' || p.startsWith('~/')) && env.home) {
    p = path.join(env.home, p.slice(1));
  }
  if (!path.isAbsolute(p) && env.workspaceRoot && (p.includes('/') || p.includes('\\'))) {
    p = path.join(env.workspaceRoot, p);
  }
  return p;
}

/** Looks `name` up in the PATH, as a shell would. */
export function onPath(env: DiscoveryEnv, name: string): string | undefined {
  const separator = env.platform === 'win32' ? ';' : ':';
  for (const dir of env.pathVar.split(separator)) {
    if (dir === '') {
      continue;
    }
    const candidate = path.join(dir, exe(env, name));
    if (env.isExecutable(candidate)) {
      return candidate;
    }
  }
  return undefined;
}

/**
 * Finds the server. A setting that names a missing file is an error rather
 * than a silent fall-back: the user asked for that binary.
 */
export function findServer(env: DiscoveryEnv, setting: string | undefined): Found | NotFound {
  if (setting && setting.trim() !== '') {
    const resolved = resolveSetting(env, setting);
    const isBareName = !resolved.includes('/') && !resolved.includes('\\');
    const command = isBareName ? onPath(env, resolved) : resolved;
    if (command && env.isExecutable(command)) {
      return { kind: 'found', command, source: 'setting' };
    }
    return {
      kind: 'not-found',
      badSetting: true,
      message:
        `The SeMo language server was not found at "${setting}" (setting semo.server.path). ` +
        'Fix the path in the settings, or clear it to use the bundled server or `semo` on the PATH.',
    };
  }
  for (const candidate of bundledCandidates(env)) {
    if (env.isExecutable(candidate)) {
      return { kind: 'found', command: candidate, source: 'bundled' };
    }
  }
  const fromPath = onPath(env, 'semo');
  if (fromPath) {
    return { kind: 'found', command: fromPath, source: 'path' };
  }
  return {
    kind: 'not-found',
    badSetting: false,
    message:
      'The SeMo language server (`semo`) was not found: it is not bundled with this extension ' +
      'and not on the PATH. Build it (`cargo build --release` gives target/release/semo) and ' +
      'set semo.server.path to it, or put `semo` on the PATH.',
  };
}
