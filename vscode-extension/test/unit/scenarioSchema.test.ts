// The scenario JSON Schema the extension contributes (`jsonValidation`)
// agrees with the scenario the simulator reads: the repository's scenarios
// and the documented example are valid, the documented keys are all there,
// and the mistakes the simulator refuses are refused.

import Ajv from 'ajv';
import { strict as assert } from 'node:assert';
import * as fs from 'node:fs';
import * as path from 'node:path';
import { test } from 'node:test';

// Compiled to out/test/unit/: the extension's folder is three levels up.
const extension = path.join(__dirname, '..', '..', '..');
const repo = path.join(extension, '..');
const schema = JSON.parse(
  fs.readFileSync(path.join(extension, 'schemas', 'scenario.schema.json'), 'utf8'),
);
const validate = new Ajv({ allErrors: true }).compile(schema);
const docs = fs.readFileSync(path.join(repo, 'docs', 'scenario-and-trace.md'), 'utf8');

function valid(scenario: unknown): boolean {
  return validate(scenario) as boolean;
}

test('the package contributes the schema for *.scenario.json', () => {
  const manifest = JSON.parse(fs.readFileSync(path.join(extension, 'package.json'), 'utf8'));
  assert.deepEqual(manifest.contributes.jsonValidation, [
    { fileMatch: '*.scenario.json', url: './schemas/scenario.schema.json' },
  ]);
});

test("the repository's scenario and the documented example are valid", () => {
  const fixture = path.join(repo, 'tests', 'fixtures', 'build', 'scouting.scenario.json');
  assert.ok(valid(JSON.parse(fs.readFileSync(fixture, 'utf8'))), JSON.stringify(validate.errors));
  const example = docs.split('## The scenario')[1].split('```json')[1].split('```')[0];
  assert.ok(valid(JSON.parse(example)), JSON.stringify(validate.errors));
});

test('every documented key is in the schema', () => {
  const section = docs.split('## The scenario')[1].split('## The trace')[0];
  const keys = [...section.matchAll(/^\| `([a-z_.R]+)` \|/gm)].map((m) => m[1]);
  assert.ok(keys.includes('robots.R.battery') && keys.includes('expect'), keys.join(' '));
  for (const key of keys) {
    let at = schema;
    for (const part of key.split('.')) {
      at = part === 'R' ? at.additionalProperties : at.properties?.[part];
      assert.ok(at, `the schema has no ${key}`);
    }
  }
});

test('the mistakes the simulator refuses are refused', () => {
  const wrong: unknown[] = [
    { duration: 'soon' },
    { durration: 1000 },
    { version: 2 },
    { faults: [{ at: 100, kill: 'a', restart: 'a' }] },
    { faults: [{ from: 1, until: 2, drop: ['a'] }] },
    { operator: [{ at: 1, every: 5, to: 'a', value: 'X', is: 1 }] },
    { network: { loss: 1.5 } },
    { expect: [{ robot: 'a' }] },
    { expect: [{ leads_to: [{ robot: 'a', in: 'M' }] }] },
    { expect: [{ always: { not: { robot: 'a', in: 'M' }, robot: 'a' } }] },
    { expect: [{ eventually: { any: [] } }] },
    { robots: { a: { sensors: [{ at: 0, value: 'X' }] } } },
  ];
  for (const scenario of wrong) {
    assert.equal(valid(scenario), false, JSON.stringify(scenario));
  }
  assert.ok(valid({ expect: [{ robot: 'a', receives: 'T.K', from: 'b', before: 10 }] }));
  assert.ok(
    valid({
      expect: [
        { always: { not: { all: [{ robot: 'a', in: 'M' }, { robot: 'b', in: 'N' }] } } },
        { eventually: { robot: 'a', enters: 'M' } },
        { leads_to: [{ robot: 'a', enters: 'M' }, { any: [{ robot: 'b', receives: 'T.K', from: 'a' }] }] },
      ],
    }),
    JSON.stringify(validate.errors),
  );
});
