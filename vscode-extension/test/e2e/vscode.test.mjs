// The extension in the real VS Code (code-server), driven by headless
// Chromium: scripts/e2e.sh starts code-server on a copy of
// test/e2e/workspace and sets SEMO_E2E_URL. One test, in the order a user
// goes: open the mission, see its error, open the Robots panel, insert a
// service, run palette commands. Screenshots go to $SEMO_E2E_OUT/shots.

import { strict as assert } from 'node:assert';
import { existsSync, readdirSync } from 'node:fs';
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
  // The status bar item says the server is ready.
  await waitForText('.statusbar-item', /SeMo server is ready|SeMo/);

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
  await waitForText('.notifications-toasts .notification-list-item', /code generated in/);
  await shot('generate-code');
  const robot = join(workspace, 'generated', 'Rovers', 'r_0');
  assert.ok(existsSync(join(robot, 'control_task.c')), `control_task.c in ${robot}`);
  assert.ok(existsSync(join(robot, 'Makefile')), `Makefile in ${robot}`);

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
