// Copies the TextMate grammar from ../grammars into the extension: a .vsix
// holds only files under the extension folder, and the grammar has one home.
import { copyFileSync, mkdirSync, existsSync } from 'node:fs';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';

const root = join(dirname(fileURLToPath(import.meta.url)), '..');
const source = join(root, '..', 'grammars', 'semo.tmLanguage.json');
const target = join(root, 'syntaxes', 'semo.tmLanguage.json');
if (!existsSync(source)) {
  console.error(`copy-grammar: ${source} is missing (the TextMate grammar lives in grammars/)`);
  process.exit(1);
}
mkdirSync(dirname(target), { recursive: true });
copyFileSync(source, target);
console.log(`copy-grammar: ${source} -> ${target}`);
