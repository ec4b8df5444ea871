// Tokenizes every example mission with the TextMate grammar, as VS Code does, and fails
// if any token is scoped `invalid` (a character the grammar does not expect). The examples
// are the repository's examples/ (the reference missions among them) and the
// formatter's fixtures (valid missions in many layouts).
'use strict';

const fs = require('fs');
const path = require('path');
const vsctm = require('vscode-textmate');
const oniguruma = require('vscode-oniguruma');

const repo = path.resolve(__dirname, '..', '..');
const roots = [
  path.join(repo, 'examples'),
  path.join(repo, 'tests', 'fixtures', 'format'),
];

function missions(dir) {
  if (!fs.existsSync(dir)) return [];
  return fs.readdirSync(dir, { withFileTypes: true }).flatMap((entry) => {
    const full = path.join(dir, entry.name);
    if (entry.isDirectory()) return missions(full);
    return entry.name.endsWith('.mission') ? [full] : [];
  });
}

async function main() {
  const wasm = fs.readFileSync(require.resolve('vscode-oniguruma/release/onig.wasm'));
  await oniguruma.loadWASM(wasm.buffer.slice(wasm.byteOffset, wasm.byteOffset + wasm.byteLength));
  const registry = new vsctm.Registry({
    onigLib: Promise.resolve({
      createOnigScanner: (sources) => new oniguruma.OnigScanner(sources),
      createOnigString: (text) => new oniguruma.OnigString(text),
    }),
    loadGrammar: async (scope) => {
      if (scope !== 'source.semo') return null;
      const file = path.join(__dirname, '..', 'semo.tmLanguage.json');
      return vsctm.parseRawGrammar(fs.readFileSync(file, 'utf8'), file);
    },
  });
  const grammar = await registry.loadGrammar('source.semo');

  const files = roots.flatMap(missions);
  if (files.length === 0) throw new Error(`no example missions under ${roots.join(', ')}`);
  const problems = [];
  for (const file of files) {
    let state = vsctm.INITIAL;
    const lines = fs.readFileSync(file, 'utf8').split(/\r?\n/);
    lines.forEach((line, i) => {
      const result = grammar.tokenizeLine(line, state);
      for (const token of result.tokens) {
        if (token.scopes.some((scope) => scope.startsWith('invalid'))) {
          const text = line.slice(token.startIndex, token.endIndex);
          problems.push(`${path.relative(repo, file)}:${i + 1}:${token.startIndex + 1}: ` +
            `${JSON.stringify(text)} is ${token.scopes.join(' ')}`);
        }
      }
      state = result.ruleStack;
    });
  }
  if (problems.length > 0) {
    console.error(problems.join('\n'));
    throw new Error(`${problems.length} invalid tokens`);
  }
  console.log(`tokenized ${files.length} example missions without invalid scopes`);
}

main().catch((error) => {
  console.error(error.message);
  process.exit(1);
});
