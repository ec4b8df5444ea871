import { strict as assert } from 'node:assert';
import { readFileSync } from 'node:fs';
import { join } from 'node:path';
import { test } from 'node:test';
import { MISSION_TEMPLATE, missionTemplateSnippet } from '../../src/pure/template';

// Compiled to out/test/unit/: the extension folder is three levels up.
const extension = join(__dirname, '..', '..', '..');
const repo = join(extension, '..');

interface Snippet {
  prefix: string | string[];
  body: string | string[];
  description: string;
}

const snippets: Record<string, Snippet> = JSON.parse(
  readFileSync(join(extension, 'snippets', 'semo.json'), 'utf8'),
);
const body = (s: Snippet) => (Array.isArray(s.body) ? s.body.join('\n') : s.body);

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
  assert.equal(body(snippets['mission template']), missionTemplateSnippet());
  assert.ok(missionTemplateSnippet().includes('{\n\t$0\n}'));
});

test('every construct has a snippet, under the server’s labels', () => {
  const rust = readFileSync(join(repo, 'compiler', 'src', 'ide', 'mission', 'snippets.rs'), 'utf8');
  const serverLabels = [...rust.matchAll(/label: "([^"]+)"/g)].map((m) => m[1]);
  for (const label of serverLabels) {
    if (label === 'mission template' || snippets[label]) {
      continue;
    }
    assert.fail(`the server's snippet "${label}" has no counterpart in snippets/semo.json`);
  }
  for (const construct of ['formation', 'composite service', 'mode', 'main', 'case', 'catch', '[[ group ]]', 'if else', 'repeat']) {
    assert.ok(snippets[construct], construct);
  }
});

test('snippet bodies are well formed: placeholders closed, tab stops numbered', () => {
  for (const [label, s] of Object.entries(snippets)) {
    const text = body(s);
    let depth = 0;
    for (let i = 0; i < text.length; i++) {
      if (text[i] === '\\') {
        i++;
      } else if (text.startsWith('${', i)) {
        depth++;
        i++;
      } else if (text[i] === '}' && depth > 0) {
        depth--;
      }
    }
    assert.equal(depth, 0, `${label}: unclosed placeholder`);
    assert.ok(s.description.length > 0, `${label}: description`);
  }
});
