import { strict as assert } from 'node:assert';
import { test } from 'node:test';
import { DiscoveryEnv, findServer } from '../../src/pure/discovery';

/** An environment whose executable files are exactly `files`. */
function env(files: string[], overrides: Partial<DiscoveryEnv> = {}): DiscoveryEnv {
  return {
    platform: 'linux',
    pathVar: '/usr/local/bin:/usr/bin',
    extensionRoot: '/ext',
    workspaceRoot: '/ws',
    home: '/home/me',
    isExecutable: (f) => files.includes(f),
    ...overrides,
  };
}

test('the setting wins over a bundled binary and the PATH', () => {
  const found = findServer(env(['/opt/semo', '/ext/server/semo', '/usr/bin/semo']), '/opt/semo');
  assert.deepEqual(found, { kind: 'found', command: '/opt/semo', source: 'setting' });
});

test('a relative setting is relative to the workspace, ~ to the home folder', () => {
  assert.deepEqual(findServer(env(['/ws/target/release/semo']), 'target/release/semo'), {
    kind: 'found',
    command: '/ws/target/release/semo',
    source: 'setting',
  });
  assert.deepEqual(findServer(env(['/home/me/bin/semo']), '~/bin/semo'), {
    kind: 'found',
    command: '/home/me/bin/semo',
    source: 'setting',
  });
});

test('a bare name in the setting is looked up in the PATH', () => {
  assert.deepEqual(findServer(env(['/usr/bin/semo-dev']), 'semo-dev'), {
    kind: 'found',
    command: '/usr/bin/semo-dev',
    source: 'setting',
  });
});

test('a setting naming a missing file is an error, not a silent fall-back', () => {
  const found = findServer(env(['/ext/server/semo', '/usr/bin/semo']), '/nowhere/semo');
  assert.equal(found.kind, 'not-found');
  assert.ok(found.kind === 'not-found' && found.badSetting);
  assert.match(found.kind === 'not-found' ? found.message : '', /\/nowhere\/semo.*semo\.server\.path/);
});

test('without a setting: the bundled server, server/ before bin/', () => {
  assert.deepEqual(findServer(env(['/ext/bin/semo', '/ext/server/semo', '/usr/bin/semo']), ''), {
    kind: 'found',
    command: '/ext/server/semo',
    source: 'bundled',
  });
  assert.deepEqual(findServer(env(['/ext/bin/semo', '/usr/bin/semo']), undefined), {
    kind: 'found',
    command: '/ext/bin/semo',
    source: 'bundled',
  });
});

test('then the first semo on the PATH', () => {
  assert.deepEqual(findServer(env(['/usr/bin/semo', '/usr/local/bin/semo']), '  '), {
    kind: 'found',
    command: '/usr/local/bin/semo',
    source: 'path',
  });
});

test('on Windows the binary is semo.exe and the PATH is split on ;', () => {
  const windows = env(['C:\\tools/semo.exe'], { platform: 'win32', pathVar: 'C:\\nothing;C:\\tools' });
  const found = findServer(windows, undefined);
  assert.equal(found.kind, 'found');
  assert.ok(found.kind === 'found' && found.command.endsWith('semo.exe'));
});

test('nothing found: the message says how to fix it', () => {
  const found = findServer(env([]), undefined);
  assert.equal(found.kind, 'not-found');
  assert.ok(found.kind === 'not-found' && !found.badSetting);
  assert.match(found.kind === 'not-found' ? found.message : '', /semo\.server\.path/);
  assert.match(found.kind === 'not-found' ? found.message : '', /PATH/);
});
