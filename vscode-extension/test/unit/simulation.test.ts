import { strict as assert } from 'node:assert';
import { test } from 'node:test';
import { missionLine, scenarioCandidates, simulationPage } from '../../src/pure/simulation';

test("the mission's own scenario comes first, then the others by name", () => {
  assert.deepEqual(
    scenarioCandidates('scouting.mission', [
      'z.scenario.json',
      'scouting.mission',
      'a.scenario.json',
      'scouting.scenario.json',
      'notes.json',
    ]),
    ['scouting.scenario.json', 'a.scenario.json', 'z.scenario.json'],
  );
  assert.deepEqual(scenarioCandidates('m.mission', ['m.json', 'README.md']), []);
});

test('a data-line names a 1-based mission line; 0 and junk name none', () => {
  assert.equal(missionLine('12'), 11);
  assert.equal(missionLine('1'), 0);
  assert.equal(missionLine('0'), undefined);
  assert.equal(missionLine(null), undefined);
  assert.equal(missionLine('3; alert(1)'), undefined);
});

test('the page escapes the summary, keeps the SVG and allows only its own script', () => {
  const page = simulationPage('T', 'a <b> & "c"', '<svg data-end-ms="1"></svg>', 'N0NCE');
  assert.ok(page.includes('a &lt;b&gt; &amp; &quot;c&quot;'));
  assert.ok(page.includes('<svg data-end-ms="1"></svg>'));
  assert.ok(page.includes("script-src 'nonce-N0NCE'"));
  assert.equal(page.match(/<script/g)?.length, 1);
  assert.ok(page.includes('<script nonce="N0NCE">'));
  // The timeline scales to the view's width, and scrolls below a readable width, instead of
  // being clipped.
  assert.ok(page.includes('<div class="timeline"><svg data-end-ms="1"></svg></div>'));
  assert.match(page, /\.timeline \{ overflow-x: auto; \}/);
  assert.match(page, /\.timeline svg \{ width: 100%; min-width: 900px; height: auto; \}/);
});
