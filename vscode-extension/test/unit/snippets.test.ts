import { strict as assert } from 'node:assert';
import { existsSync, readFileSync } from 'node:fs';
import { join } from 'node:path';
import { test } from 'node:test';
import { MISSION_TEMPLATE, missionTemplateSnippet } from '../../src/pure/template';

// Compiled to out/test/unit/: the extension folder is three levels up.
const extension = join(__dirname, '..', '..', '..');
const repo = join(extension, '..');

/** The body of a Rust string literal `const NAME: &str = "\` ... `";`. */
function rustConst(source: string, name: string): string {
  const start = source.indexOf(`pub const ${name}: &str = "\\\n`);
  assert.ok(start >= 0, `${name} in snippets.rs`);
  const from = source.indexOf('\n', start) + 1;
  const end = source.indexOf('";', from);
  return source.slice(from, end).replace(/\\"/g, '"').replace(/\\\\/g, '\\');
}

test('the template is the server’s MISSION_TEMPLATE (compiler/src/ide/mission/snippets.rs)', () => {
  const rust = readFileSync(join(repo, 'compiler', 'src', 'ide', 'mission', 'snippets.rs'), 'utf8');
  assert.equal(MISSION_TEMPLATE, rustConst(rust, 'MISSION_TEMPLATE'));
});

test('the template snippet puts the cursor inside the formation', () => {
  assert.ok(missionTemplateSnippet().includes('{\n\t$0\n}'));
});

// VS Code lists a contributed snippet wherever its prefix is typed, beside the
// server's items: `send` twice in a service body, a mode's or a formation's
// skeleton among statements. The server offers each construct's snippet only
// where it may be written, so the extension contributes none.
test('the extension contributes no snippets of its own: they come from the server', () => {
  const manifest = JSON.parse(readFileSync(join(extension, 'package.json'), 'utf8'));
  assert.equal(manifest.contributes.snippets, undefined);
  assert.ok(!manifest.categories.includes('Snippets'));
  assert.ok(!existsSync(join(extension, 'snippets')));
});
