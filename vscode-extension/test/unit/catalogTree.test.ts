import { strict as assert } from 'node:assert';
import { test } from 'node:test';
import { buildTree, serviceCallSnippet, TreeNode } from '../../src/pure/catalogTree';

/** A `semo/catalog` answer shaped as server/src/handlers/catalog.rs writes it. */
const CATALOG = {
  robots: [
    {
      name: 'TIEvalbot',
      aliases: ['ti'],
      doc: 'A small wheeled robot.',
      capabilities: ['move'],
      services: [
        {
          name: 'move',
          signature: 'move(distance: number, speed?: number)',
          params: [
            { name: 'distance', type: 'number', optional: false },
            { name: 'speed', type: 'number', optional: true },
          ],
          doc: 'Drives straight.',
        },
        { name: 'beep', signature: 'beep()', params: [], doc: null },
      ],
      values: [{ name: 'COLOR', type: 'string', unit: null, doc: 'The colour seen.' }],
    },
    {
      name: 'Drone',
      aliases: [],
      doc: null,
      capabilities: [],
      services: [],
      values: [{ name: 'altitude', type: 'number', unit: 'm', doc: null }],
    },
  ],
  user: {
    name: 'USER',
    aliases: [],
    doc: 'The operator.',
    capabilities: [],
    services: [{ name: 'notify', params: [{ name: 'text', type: 'string', optional: false }] }],
    values: [],
  },
};

/** The tree as indented lines: `label — description`, then `⇒ insertion`. */
function outline(nodes: TreeNode[], depth = 0): string[] {
  return nodes.flatMap((n) => {
    const insert = n.insert ? ('snippet' in n.insert ? ` ⇒ ${n.insert.snippet}` : ` ⇒ ${n.insert.text}`) : '';
    const line = `${'  '.repeat(depth)}${n.label}${n.description ? ` — ${n.description}` : ''}${insert}`;
    return [line, ...outline(n.children, depth + 1)];
  });
}

test('robot types by name, their services with parameters and values with types', () => {
  assert.deepEqual(outline(buildTree(CATALOG)), [
    'Drone',
    '  values — 1',
    '    altitude — number (m) ⇒ altitude',
    'TIEvalbot — ti',
    '  services — 2',
    '    beep — () ⇒ beep()',
    '    move — (distance: number, speed?: number) ⇒ move(${1:distance})$0',
    '  values — 1',
    '    COLOR — string ⇒ COLOR',
    'USER — operator console, not a robot type',
    '  services — 1',
    '    notify — (text: string) ⇒ notify(${1:text})$0',
  ]);
});

test('the operator console is not listed as a robot type', () => {
  const tree = buildTree(CATALOG);
  assert.deepEqual(
    tree.filter((n) => n.kind === 'robot').map((n) => n.label),
    ['Drone', 'TIEvalbot'],
  );
  const user = tree[tree.length - 1];
  assert.equal(user.kind, 'operator');
  assert.match(user.tooltip!, /not a robot type/);
});

test('tooltips carry the signature and the doc', () => {
  const tree = buildTree(CATALOG);
  const ti = tree.find((n) => n.label === 'TIEvalbot')!;
  assert.match(ti.tooltip!, /\*\*TIEvalbot\*\*[\s\S]*A small wheeled robot\.[\s\S]*capabilities: move/);
  const move = ti.children[0].children.find((n) => n.label === 'move')!;
  assert.equal(move.tooltip, '`move(distance: number, speed?: number)`\n\nDrives straight.');
  const color = ti.children[1].children[0];
  assert.equal(color.tooltip, '`COLOR: string`\n\nThe colour seen.');
});

test('ids are unique and stable', () => {
  const ids: string[] = [];
  const walk = (nodes: TreeNode[]) => nodes.forEach((n) => (ids.push(n.id), walk(n.children)));
  walk(buildTree(CATALOG));
  assert.equal(new Set(ids).size, ids.length);
  assert.ok(ids.includes('TIEvalbot/services/move'));
});

test('call snippets follow the server completion rule', () => {
  assert.equal(serviceCallSnippet({ name: 'stop', params: [] }), 'stop()');
  assert.equal(
    serviceCallSnippet({ name: 'look', params: [{ name: 'angle', type: 'number', optional: true }] }),
    'look($1)$0',
  );
  assert.equal(
    serviceCallSnippet({
      name: 'go$',
      params: [
        { name: 'x}', type: 'number' },
        { name: 'y', type: 'number' },
      ],
    }),
    'go\\$(${1:x\\}}, ${2:y})$0',
  );
});

test('a malformed answer gives an empty tree, never an exception', () => {
  for (const bad of [null, undefined, 42, 'x', {}, { robots: 'no' }, { robots: [{ name: 1 }] }, { robots: [null] }]) {
    assert.deepEqual(buildTree(bad), []);
  }
  // A good robot beside a bad one is kept.
  assert.equal(buildTree({ robots: [{ name: 'A', services: [], values: [] }, { name: 'B' }] }).length, 1);
});
