import { strict as assert } from 'node:assert';
import { test } from 'node:test';
import {
  ConflictRefusal,
  GenerateArguments,
  conflictRefusal,
  forcePrompt,
  generateWithConsent,
} from '../../src/pure/generate';

/** A JSON-RPC error as vscode-languageclient rejects with (`ResponseError`). */
function responseError(message: string, data?: unknown): Error {
  return Object.assign(new Error(message), { code: -32803, data });
}

const REFUSED = responseError(
  'generation would replace 1 file(s) that are not as semo wrote them:\n  out/Team1/create1/tasks/follow.c: changed since it was generated',
  {
    conflicts: [
      { path: 'out/Team1/create1/tasks/follow.c', why: 'changed since it was generated' },
    ],
  },
);

/** A server answering from `answers` in turn, recording what it was sent. */
function server(answers: Array<() => unknown>) {
  const sent: GenerateArguments[] = [];
  const send = async (args: GenerateArguments) => {
    sent.push(args);
    const next = answers.shift();
    if (!next) {
      throw new Error('no more answers');
    }
    return next();
  };
  return { sent, send };
}

const ARGS: GenerateArguments = { uri: 'file:///ws/follow.mission', outputFolder: '/ws/out' };

test('a refusal over files in the way asks, and re-sends with force when agreed', async () => {
  const { sent, send } = server([
    () => {
      throw REFUSED;
    },
    () => ({ robots: [] }),
  ]);
  const asked: ConflictRefusal[] = [];
  const outcome = await generateWithConsent(send, ARGS, async (r) => {
    asked.push(r);
    return true;
  });
  assert.deepEqual(outcome, { kind: 'done', value: { robots: [] }, forced: true });
  assert.equal(asked.length, 1);
  assert.equal(asked[0].conflicts[0].path, 'out/Team1/create1/tasks/follow.c');
  assert.deepEqual(sent, [ARGS, { ...ARGS, force: true }]);
});

test('declining the modal sends nothing more', async () => {
  const { sent, send } = server([
    () => {
      throw REFUSED;
    },
  ]);
  const outcome = await generateWithConsent(send, ARGS, async () => false);
  assert.equal(outcome.kind, 'declined');
  assert.deepEqual(sent, [ARGS]);
});

test('other failures are not offered force', async () => {
  for (const error of [
    responseError('the output folder ../x is outside the workspace'),
    responseError('another generation is writing', null),
    responseError('odd data', { conflicts: [] }),
    responseError('odd data', { conflicts: [{ why: 'no path' }] }),
    'a string',
    undefined,
  ]) {
    const { sent, send } = server([
      () => {
        throw error;
      },
    ]);
    let asked = false;
    const outcome = await generateWithConsent(send, ARGS, async () => {
      asked = true;
      return true;
    });
    assert.deepEqual(outcome, { kind: 'failed', error });
    assert.equal(asked, false);
    assert.deepEqual(sent, [ARGS]);
  }
});

test('a forced request that is refused again is a failure, not a loop', async () => {
  const { sent, send } = server([
    () => {
      throw REFUSED;
    },
    () => {
      throw REFUSED;
    },
  ]);
  const outcome = await generateWithConsent(send, ARGS, async () => true);
  assert.deepEqual(outcome, { kind: 'failed', error: REFUSED });
  assert.equal(sent.length, 2);
});

test('a generation that succeeds at once asks nothing', async () => {
  const { send } = server([() => ({ robots: [1] })]);
  const outcome = await generateWithConsent(send, ARGS, async () => {
    throw new Error('asked');
  });
  assert.deepEqual(outcome, { kind: 'done', value: { robots: [1] }, forced: false });
});

test('the modal names every file and where they are saved', () => {
  const refusal = conflictRefusal(
    responseError('m', {
      conflicts: [
        { path: 'a/tasks/x.c', why: 'changed since it was generated' },
        { path: 'a/notes.txt', why: 'not written by semo' },
      ],
    }),
  );
  assert.ok(refusal);
  const prompt = forcePrompt(refusal);
  assert.match(prompt.message, /2 files/);
  assert.match(prompt.detail, /a\/tasks\/x\.c: changed since it was generated/);
  assert.match(prompt.detail, /a\/notes\.txt: not written by semo/);
  assert.match(prompt.detail, /\.semo-backup\//);
});
