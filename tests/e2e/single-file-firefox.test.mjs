// dist/cutroute.html in Firefox: the single file opened from file:// as a double-click does,
// driven over WebDriver BiDi (firefox.mjs), with the same checks as in Chromium.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { pathToFileURL } from 'node:url';
import { distDir, projectRoot, cli, assertRounded } from './harness.mjs';
import { launchFirefox } from './firefox.mjs';

test('the single-file page opens from file:// in Firefox, solves in its worker and opens local files', async () => {
  const file = path.join(distDir, 'cutroute.html');
  assert.ok(fs.existsSync(file), `no ${file}: run scripts/build-release.sh`);
  const alone = fs.mkdtempSync(path.join(fs.realpathSync('/tmp'), 'cutroute-usb-'));
  fs.copyFileSync(file, path.join(alone, 'cutroute.html'));
  const page = await launchFirefox();
  try {
    await page.goto(pathToFileURL(path.join(alone, 'cutroute.html')).href);
    // The default sample is drawn from the bytes the page carries.
    await page.waitFor(`document.querySelector('#file-name')?.textContent.includes('E1X_6_01')`);
    assert.equal(await page.evaluate(`document.querySelectorAll('#nest-view path.part').length`), 8);
    const run = async (solver, seconds) => {
      await page.evaluate(`(() => {
        const solver = document.querySelector('#solver');
        solver.value = ${JSON.stringify(solver)};
        solver.dispatchEvent(new Event('change', { bubbles: true }));
        const limit = document.querySelector('#time-limit');
        limit.value = ${JSON.stringify(String(seconds))};
        limit.dispatchEvent(new Event('input', { bubbles: true }));
        limit.dispatchEvent(new Event('change', { bubbles: true }));
      })()`);
      await page.evaluate(`document.querySelector('#start').click()`);
      await page.waitFor(`['finished', 'failed'].some((s) => document.querySelector('#job-status')?.textContent.startsWith(s))`);
      assert.equal(await page.evaluate(`document.querySelector('#job-status').textContent`), 'finished', solver);
    };
    // nearest in the worker the page carries gives the CLI's route.
    await run('nearest', 1);
    const nearest = cli('solve', 'data/nests/dbs-json/E1X_6_01.dbs.json', '--solver', 'nearest', '--json');
    assert.equal(Number(await page.evaluate(`document.querySelector('#pierces').textContent`)), nearest.pierces);
    assertRounded(await page.evaluate(`document.querySelector('#idle-length').dataset.mm`), nearest.idle_length, 3, 'idle (nearest)');
    // ccp too (one pierce per contour: 16).
    await run('ccp', 1);
    assert.equal(Number(await page.evaluate(`document.querySelector('#pierces').textContent`)), 16);
    // A local file opens through the picker.
    await page.setFiles('#file-input', [path.join(projectRoot, 'data/nests/dbs/seven.dbs')]);
    await page.waitFor(`document.querySelector('#file-name')?.textContent.includes('seven')`);
    const seven = cli('inspect', 'data/nests/dbs/seven.dbs', '--json');
    assert.equal(await page.evaluate(`document.querySelectorAll('#nest-view path.part').length`), seven.parts - 1);
    assert.deepEqual(page.errors, []);
  } finally {
    await page.close();
    fs.rmSync(alone, { recursive: true, force: true });
  }
});
