// The extension in the real VS Code (code-server), driven by headless
// Chromium: scripts/e2e.sh installs the platform .vsix (the server inside it)
// and starts code-server on a copy of test/e2e/workspace with SEMO_E2E_URL
// set. Three tests, in the order a user goes: open the mission, see its error,
// open the Robots panel, insert a service, run palette commands; then edit:
// a quick fix, hover, rename, completion and format on save, served by the
// bundled server; then the Robots (live) view on a private MQTT broker
// ($SEMO_E2E_MQTT_PORT, started by e2e.sh). Screenshots go to $SEMO_E2E_OUT/shots.

import { strict as assert } from 'node:assert';
import { execFileSync } from 'node:child_process';
import { existsSync, readFileSync, readdirSync, writeFileSync } from 'node:fs';
import { join } from 'node:path';
import { after, before, test } from 'node:test';
import puppeteer from 'puppeteer-core';

const url = process.env.SEMO_E2E_URL;
const out = process.env.SEMO_E2E_OUT ?? '.';
const workspace = process.env.SEMO_E2E_WORKSPACE ?? '.';
const shots = join(out, 'shots');

let browser;
let page;

before(async () => {
  assert.ok(url, 'SEMO_E2E_URL: run through scripts/e2e.sh');
  browser = await puppeteer.launch({
    executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium',
    headless: true,
    args: [
      '--no-sandbox',
      '--disable-gpu',
      '--disable-quic',
      '--no-first-run',
      '--disable-background-networking',
      '--disable-component-update',
      '--disable-sync',
      '--disable-dev-shm-usage',
    ],
    defaultViewport: { width: 1400, height: 900 },
  });
  page = await browser.newPage();
  page.on('pageerror', (e) => console.log(`[page error] ${e.message}`));
});

after(async () => {
  await browser?.close();
});

/** Waits until some element matching `selector` has text matching `pattern`. */
async function waitForText(selector, pattern, timeout = 60000) {
  const handle = await page.waitForFunction(
    (sel, source, flags) => {
      const re = new RegExp(source, flags);
      return [...document.querySelectorAll(sel)].find((e) =>
        re.test(e.textContent + ' ' + (e.getAttribute('aria-label') ?? '')),
      );
    },
    { timeout, polling: 250 },
    selector,
    pattern.source,
    pattern.flags,
  );
  return handle.asElement();
}

async function shot(name) {
  const file = join(shots, `${name}.png`);
  await page.screenshot({ path: file });
  console.log(`screenshot: ${file}`);
}

/** Runs a palette command by its title; returns once the palette closed. */
async function runCommand(title) {
  await page.keyboard.press('F1');
  await page.waitForSelector('.quick-input-widget .quick-input-box input', { visible: true });
  await page.keyboard.type(title);
  await waitForText('.quick-input-list .monaco-list-row', new RegExp(escapeRe(title)));
  await page.keyboard.press('Enter');
}

function escapeRe(text) {
  return text.replace(/[.*+?^${}()|[\]\\]/g, '\\$&');
}

test('a mission in VS Code: error squiggle, Robots panel, commands', { timeout: 240000 }, async () => {
  try {
    await userJourney();
  } catch (e) {
    await shot('failure').catch(() => {});
    throw e;
  }
});

async function userJourney() {
  await page.goto(url, { waitUntil: 'domcontentloaded' });
  await page.waitForSelector('.monaco-workbench', { timeout: 90000 });

  // Open the mission from the explorer.
  const row = await waitForText('.explorer-folders-view .monaco-list-row', /scouts\.mission/, 90000);
  await row.click();
  await page.waitForSelector('.monaco-editor .view-lines', { visible: true });
  await waitForText('.monaco-editor .view-lines', /Scouts:\sRovr/);

  // The server's diagnostic: a squiggle under `Rovr`, and one error in the status bar.
  await page.waitForSelector('.monaco-editor .squiggly-error', { timeout: 90000 });
  const problems = await page.$eval('[id="status.problems"]', (e) => e.getAttribute('aria-label') ?? e.textContent);
  assert.match(problems, /\b1\b/, `problems status: ${problems}`);
  // The extension's status bar item says the server is ready.
  await page.waitForFunction(
    () => {
      const item = document.querySelector('.statusbar-item[id^="semo.semo"]');
      return item?.querySelector('.codicon-check') && item.textContent.trim() === 'SeMo';
    },
    { timeout: 60000, polling: 250 },
  );

  // The Robots panel lists the workspace's robot type and the built-in ones.
  const robots = await page.waitForSelector('.activitybar .action-item a[aria-label^="SeMo Robots"], .activitybar .action-item [aria-label^="SeMo Robots"]');
  await robots.click();
  const rover = await waitForText('.pane-body .monaco-list-row', /^\s*Rover/);
  await waitForText('.pane-body .monaco-list-row', /iRobotCreate/);
  await rover.click();
  const drive = await waitForText('.pane-body .monaco-list-row', /drive\s*\(distance: int, speed\?: int\)/);
  await shot('robots-panel');

  // Clicking a service writes its call at the cursor: after `repeat(1 SEC)` on a new line.
  await page.click('.monaco-editor .view-lines');
  await page.keyboard.down('Control');
  await page.keyboard.press('End');
  await page.keyboard.up('Control');
  await drive.click();
  await waitForText('.monaco-editor .view-lines', /drive\(distance\)/);
  await page.keyboard.press('Escape');

  // The mode machine of the mission, drawn by the server into a webview.
  await page.click('.monaco-editor .view-lines');
  await runCommand('SeMo: Show Mode Machine');
  const drawn = await waitForFrameContent(/data-team="Scouts"/, 60000);
  assert.ok(drawn, 'the mode machine webview shows the Scouts team');
  await shot('mode-machine');

  // Check Workspace: the server re-reads the workspace; the Problems view
  // opens on the mission's error.
  await page.click('.monaco-editor .view-lines');
  await runCommand('SeMo: Check Workspace');
  await waitForText('.markers-panel .monaco-list-row', /unknown robot type `Rovr`/);

  // Generate Code is in the palette. This mission has errors: the server
  // refuses and says why.
  await page.click('.monaco-editor .view-lines');
  await runCommand('SeMo: Generate Code');
  const refused = await waitForText(
    '.notifications-toasts .notification-list-item',
    /code generation refused|code generation failed/,
  );
  assert.match(await refused.evaluate((e) => e.textContent), /refused/);
  // One notification for one generation: the server, told at start-up that
  // this client shows the outcome, shows none of its own (it sends its
  // messages before its answer, so one would be on screen by now).
  assert.equal(await toastsMatching(/code generation refused/), 1, 'one refusal notification');
  await shot('generate-refused');

  // A mission without errors: its robots' folders are written.
  await page.keyboard.down('Control');
  await page.keyboard.press('KeyP');
  await page.keyboard.up('Control');
  await page.waitForSelector('.quick-input-widget .quick-input-box input', { visible: true });
  await page.keyboard.type('rovers.mission');
  await waitForText('.quick-input-list .monaco-list-row', /rovers\.mission/);
  await page.keyboard.press('Enter');
  await waitForText('.tabs-container .tab.active', /rovers\.mission/);
  // The new editor is focused once its text is laid out.
  await waitForText('.monaco-editor .view-lines', /Rovers\.Explore\.Wander/);
  await runCommand('SeMo: Generate Code');
  await waitForText('.notifications-toasts .notification-list-item', /code generated for 2 robot\(s\) in/);
  assert.equal(await toastsMatching(/generated/), 1, 'one notification for the generation');
  await shot('generate-code');
  // No output folder setting: where `semo build` writes, `out` beside the mission.
  const robot = join(workspace, 'out', 'Rovers', 'r_0');
  assert.ok(existsSync(join(robot, 'control_task.c')), `control_task.c in ${robot}`);
  assert.ok(existsSync(join(robot, 'Makefile')), `Makefile in ${robot}`);

  // Show Task Graph on the mission: its robots offered, the one picked drawn
  // (its refined task graph, the generated taskgraph.xml's picture).
  await page.click('.monaco-editor .view-lines');
  await runCommand('SeMo: Show Task Graph');
  await waitForText('.quick-input-list .monaco-list-row', /r_1/);
  await page.keyboard.type('r_1');
  await page.keyboard.press('Enter');
  await waitForText('.tabs-container .tab', /Task Graph: r_1 \(rovers\.mission\)/);
  assert.ok(await waitForFrameContent(/ControlTask/, 60000), 'the robot task graph webview shows its control task');
  await shot('robot-task-graph');

  // Simulate Mission: the timeline of rovers.scenario.json, both robots'
  // lanes, scaled to the view and scrolled to its right end, none of it
  // clipped (it was cut off on the right).
  await page.click('.monaco-editor .view-lines');
  await runCommand('SeMo: Simulate Mission');
  assert.ok(await waitForFrameContent(/data-robot="r_1"/, 60000), 'the timeline shows r_1');
  const fits = await inFrameWith(/data-end-ms=/, () => {
    const timeline = document.querySelector('.timeline');
    const svg = document.querySelector('.timeline svg');
    if (!timeline || !svg) {
      return false;
    }
    timeline.scrollLeft = timeline.scrollWidth;
    return svg.getBoundingClientRect().right <= document.documentElement.clientWidth + 1;
  });
  assert.equal(fits, true, 'the timeline fits the view');
  await shot('simulation');

  // Verify Mission: the search `semo verify` makes, summed up in one
  // notification that names the mission.
  await page.click('.monaco-editor .view-lines');
  await runCommand('SeMo: Verify Mission');
  await waitForText(
    '.notifications-toasts .notification-list-item',
    /SeMo: rovers\.mission: (nothing found|\d+ finding)/,
  );
  await shot('verify');

  // A task graph's picture: open it from the explorer, then the palette.
  await page.keyboard.down('Control');
  await page.keyboard.down('Shift');
  await page.keyboard.press('KeyE');
  await page.keyboard.up('Shift');
  await page.keyboard.up('Control');
  const graphRow = await waitForText('.explorer-folders-view .monaco-list-row', /data_loop\.taskgraph\.xml/);
  await graphRow.click();
  await waitForText('.monaco-editor .view-lines', /<taskgraph|<Task/);
  await runCommand('SeMo: Show Task Graph');
  assert.ok(await waitForFrameContent(/D-loop × 10/, 60000), 'the task graph webview shows the loop');
  await shot('task-graph');

  // A new mission from the template, in an untitled editor of language SeMo.
  await runCommand('SeMo: New Mission from Template');
  await waitForText('.monaco-editor .view-lines', /#\s1\.\sTeam\sformation/);
  await waitForText('.statusbar-item', /SeMo Mission/);
  await shot('new-mission');
}

/** Runs `fn` in the first frame whose HTML matches `pattern` (undefined if none). */
async function inFrameWith(pattern, fn) {
  for (const frame of page.frames()) {
    try {
      const html = await frame.evaluate(() => document.documentElement.outerHTML);
      if (pattern.test(html)) {
        return await frame.evaluate(fn);
      }
    } catch {
      // A frame navigating away; try the next.
    }
  }
  return undefined;
}

/** How many notification toasts on screen match `pattern`. */
async function toastsMatching(pattern) {
  const texts = await page.$$eval('.notifications-toasts .notification-list-item', (items) =>
    items.map((e) => e.textContent ?? ''),
  );
  return texts.filter((t) => pattern.test(t)).length;
}

/** Waits until some frame (webviews nest two iframes deep) holds `pattern`. */
async function waitForFrameContent(pattern, timeout) {
  const deadline = Date.now() + timeout;
  while (Date.now() < deadline) {
    for (const frame of page.frames()) {
      try {
        const html = await frame.evaluate(() => document.documentElement.outerHTML);
        if (pattern.test(html)) {
          return true;
        }
      } catch {
        // A frame navigating away; try the next.
      }
    }
    await new Promise((r) => setTimeout(r, 500));
  }
  return false;
}

test('editing a mission: quick fix, hover, rename, completion, format on save', { timeout: 240000 }, async () => {
  try {
    await editingJourney();
  } catch (e) {
    await shot('editing-failure').catch(() => {});
    throw e;
  }
});

async function editingJourney() {
  // The server is the one inside the extension: the settings name none and
  // code-server's PATH has none (scripts/e2e.sh).
  const servers = await waitFor(() => {
    const found = languageServers();
    return found.length > 0 ? found : undefined;
  });
  for (const argv of servers) {
    assert.match(argv[0], /\/extensions\/semo\.semo-[^/]+\/server\/semo$/, `the server runs as ${argv.join(' ')}`);
  }

  // scouts.mission as the workspace has it (the first test inserted a call into it).
  const original = readFileSync(join(import.meta.dirname, 'workspace', 'scouts.mission'), 'utf8');
  writeFileSync(join(workspace, 'scouts.mission'), original);
  await openFile('scouts.mission');
  await runCommand('File: Revert File');
  await page.waitForFunction(
    () => !/drive\(distance/.test(document.querySelector('.editor-group-container .monaco-editor .view-lines')?.textContent),
    { timeout: 30000, polling: 250 },
  );
  await waitForText('.monaco-editor .view-lines', /Scouts:\sRovr\sr\[2\]/);
  await page.waitForSelector('.monaco-editor .squiggly-error', { timeout: 90000 });

  // Quick fix: `Rovr` becomes `Rover`, and the error goes away.
  // F8 puts the cursor on the file's first problem.
  await page.click('.editor-group-container .monaco-editor .view-lines');
  await chord('Control', 'Home');
  await page.keyboard.press('F8');
  await waitForText('.marker-widget, .zone-widget', /unknown robot type `Rovr`/);
  await page.keyboard.press('Escape');
  await chord('Control', 'Period');
  const fix = await waitForText('.action-widget .monaco-list-row', /Change `Rovr` to `Rover`/);
  await shot('quick-fix');
  await fix.click();
  await waitForText('.monaco-editor .view-lines', /Scouts:\sRover\sr\[2\]/);
  await page.waitForFunction(() => !document.querySelector('.monaco-editor .squiggly-error'), {
    timeout: 60000,
    polling: 250,
  });

  // Hover on a robot service shows its documentation from the workspace catalog.
  await goTo(7, 3); // `  drive(100)`
  await chord('Control', 'KeyK');
  await chord('Control', 'KeyI');
  await waitForText('.monaco-hover', /Drive ahead\./);
  await shot('hover');
  await page.keyboard.press('Escape');

  // Rename a mode: its declaration and its use change together.
  await goTo(10, 8); // `Scouts.SEARCH{ set(Explore, Wander) }`
  await page.keyboard.press('F2');
  await page.waitForFunction(() => document.activeElement?.closest('.rename-box'), {
    timeout: 30000,
    polling: 100,
  });
  await chord('Control', 'KeyA');
  await page.keyboard.type('ROAM');
  await page.keyboard.press('Enter');
  // (One line at a time: the editor keeps its line elements in no fixed order.)
  await waitForText('.monaco-editor .view-line', /^Scouts\.ROAM\{/);
  await waitForText('.monaco-editor .view-line', /^\s*default:\smode\s=\sROAM\s*$/);

  // Completion offers the robot's service; accepting it writes the call.
  await goTo(7, 3);
  await page.keyboard.press('End');
  await page.keyboard.press('Enter');
  await page.keyboard.type('dri');
  await chord('Control', 'Space');
  const item = await waitForText('.suggest-widget .monaco-list-row', /drive\(distance: int, speed\?: int\)/);
  const labels = await page.$$eval('.suggest-widget .monaco-list-row .label-name', (rows) =>
    rows.map((r) => r.textContent.trim()),
  );
  assert.ok(labels.includes('drive'), `completion labels: ${labels.join(', ')}`);
  await shot('completion');
  await item.click();
  await page.keyboard.press('Escape');
  await waitForText('.monaco-editor .view-line', /^\s*drive\(distance\)\s*$/);

  // Format on save: the canonical layout, in the editor and on disk.
  await chord('Control', 'KeyS');
  await waitForText('.monaco-editor .view-lines', /Scouts\.Explore\.Wander\s\{/);
  const saved = await waitFor(() => {
    const text = readFileSync(join(workspace, 'scouts.mission'), 'utf8');
    return text.includes('Scouts.Explore.Wander {') ? text : undefined;
  });
  assert.match(saved, /Scouts: Rover r\[2\]/);
  assert.match(saved, /Scouts\.ROAM \{/);
  assert.match(saved, /default: mode = ROAM/);
  assert.match(saved, /drive\(100\)\n\s+drive\(distance/);
  await shot('formatted');
}

test('Robots (live): the robots of a running mission from its broker', { timeout: 240000 }, async () => {
  try {
    await liveJourney();
  } catch (e) {
    await shot('live-failure').catch(() => {});
    throw e;
  }
});

/** Publishes what a robot of `rovers` publishes in the run `default`
 * started at Unix ms 1000: its retained status. */
function publishStatus(robot, status) {
  execFileSync('mosquitto_pub', [
    '-h', '127.0.0.1', '-p', String(process.env.SEMO_E2E_MQTT_PORT), '-q', '1', '-r',
    '-t', `semo/rovers/default/status/${robot}`,
    '-m', JSON.stringify({ robot, event: 'status', started: '1000', ...status }),
  ]);
}

async function liveJourney() {
  assert.ok(process.env.SEMO_E2E_MQTT_PORT, 'SEMO_E2E_MQTT_PORT: run through scripts/e2e.sh');
  // The monitor on rovers.mission (the broker of the semo.monitor.broker
  // setting): both robots waiting until they report.
  await openFile('rovers.mission');
  await runCommand('SeMo: Monitor Robots');
  const rows = '.pane-body .monaco-list-row';
  await waitForText(rows, /rovers.*connected/);
  await waitForText(rows, /r_1\s*waiting/);
  // A robot reports; then it vanishes and the broker sends its last will.
  publishStatus('r_0', { t: 5, state: 'running', mode: 'SEARCH', leader: '', services: 'Explore=Wander' });
  await waitForText(rows, /r_0\s*running · SEARCH/);
  await waitForText(rows, /Explore\s*Wander/);
  await shot('robots-live');
  // The robot on the pictures: the mission's SEARCH line and Wander's line
  // marked in the editor, and its mode marked in the mode machine.
  await page.waitForFunction(
    () => [...document.styleSheets].some((sheet) => {
      try {
        return [...sheet.cssRules].some((rule) => rule.cssText.includes('in this mode: r_0'));
      } catch {
        return false;
      }
    }),
    { timeout: 30000, polling: 250 },
  );
  // rovers.mission is still the visible editor (opening it again would
  // switch the side bar away from the Robots (live) view).
  await runCommand('SeMo: Show Mode Machine');
  assert.ok(
    await waitForFrameContent(/r_0 \(Rovers\) · running · SEARCH · \[Explore=Wander\]/, 60000),
    'the mode machine shows r_0 in SEARCH',
  );
  assert.ok(await waitForFrameContent(/data-mode="SEARCH"\] rect/, 10000), 'SEARCH is marked');
  await shot('mode-machine-live');
  publishStatus('r_0', { state: 'lost' });
  await waitForText(rows, /r_0\s*LOST/);
  await waitForText(rows, /r_1\s*waiting/);
  await runCommand('SeMo: Stop Monitoring');
  await page.waitForFunction(
    () => ![...document.querySelectorAll('.pane-body .monaco-list-row')].some((e) => /r_1\s*waiting/.test(e.textContent)),
    { timeout: 30000, polling: 250 },
  );
}

/** Presses `key` with `modifier` held. */
async function chord(modifier, key) {
  await page.keyboard.down(modifier);
  await page.keyboard.press(key);
  await page.keyboard.up(modifier);
}

/** Opens a workspace file from the explorer, in the first editor group. */
async function openFile(name) {
  await runCommand('View: Focus First Editor Group');
  await page.keyboard.down('Control');
  await page.keyboard.down('Shift');
  await page.keyboard.press('KeyE');
  await page.keyboard.up('Shift');
  await page.keyboard.up('Control');
  const row = await waitForText('.explorer-folders-view .monaco-list-row', new RegExp(`^\\s*${escapeRe(name)}`));
  await row.click();
  await waitForText('.tabs-container .tab.active', new RegExp(escapeRe(name)));
}

/** Puts the cursor of the active editor at `line`:`column` (Go to Line). */
async function goTo(line, column) {
  await chord('Control', 'KeyG');
  await page.waitForSelector('.quick-input-widget .quick-input-box input', { visible: true });
  await page.keyboard.type(`${line}:${column}`);
  await page.keyboard.press('Enter');
  await waitForText('.statusbar-item', new RegExp(`Ln ${line}, Col ${column}\\b`));
}

/** Polls `probe` until it returns something, for at most `timeout` ms. */
async function waitFor(probe, timeout = 30000) {
  const deadline = Date.now() + timeout;
  while (Date.now() < deadline) {
    const value = probe();
    if (value !== undefined) {
      return value;
    }
    await new Promise((r) => setTimeout(r, 250));
  }
  throw new Error(`timed out after ${timeout} ms`);
}

/** The command lines of the running `semo lsp` processes (from /proc). */
function languageServers() {
  const found = [];
  for (const pid of readdirSync('/proc').filter((p) => /^\d+$/.test(p))) {
    try {
      const argv = readFileSync(`/proc/${pid}/cmdline`, 'utf8').split('\0').filter(Boolean);
      if (argv.length >= 2 && argv[1] === 'lsp' && /(^|\/)semo$/.test(argv[0])) {
        found.push(argv);
      }
    } catch {
      // The process ended meanwhile.
    }
  }
  return found;
}
