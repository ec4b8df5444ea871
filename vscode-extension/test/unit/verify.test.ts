// "SeMo: Verify Mission"'s notification, from the server's `semo.verify` answer.

import { strict as assert } from 'node:assert';
import { test } from 'node:test';
import { VerifyAnswer, verifyMessage } from '../../src/pure/verify';

const clean: VerifyAnswer = {
  exhaustive: true,
  states: 7,
  summary: 'explored every behaviour: 7 state(s), 7 transition(s): a proof for the choices explored',
  findings: [],
  properties: [],
};

test('a clean exhaustive search is a proof, a bounded one says so', () => {
  assert.deepEqual(verifyMessage('main.mission', clean), {
    level: 'info',
    text: 'SeMo: main.mission: nothing found, every behaviour explored (7 states)',
  });
  assert.equal(
    verifyMessage('main.mission', { ...clean, exhaustive: false, states: 50000 }).text,
    'SeMo: main.mission: nothing found, bounded search (50000 states)',
  );
});

test('findings and broken properties are a warning that counts them', () => {
  const answer: VerifyAnswer = {
    ...clean,
    findings: [
      {
        code: 'V005',
        message: 'a race',
        range: { start: { line: 16, character: 2 } },
        scenario: '{}',
      },
    ],
    properties: [
      { expectation: 'eventually a in M', verdict: 'broken', proof: true, why: 'never', scenario: '{}' },
      { expectation: 'always a in M', verdict: 'holds', proof: true, why: null, scenario: null },
    ],
  };
  assert.deepEqual(verifyMessage('main.mission', answer), {
    level: 'warning',
    text: 'SeMo: main.mission: 1 finding(s), 1 broken property, every behaviour explored (7 states) (see the SeMo output)',
  });
});
