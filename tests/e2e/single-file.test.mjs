// dist/cutroute.html: the whole app in one file, opened from file:// as a double-click does.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { pathToFileURL } from 'node:url';
import { launchBrowser, watchErrors, distDir, projectRoot, cli, assertRounded } from './harness.mjs';

test('the single-file page opens from file://, solves in its worker and opens local files', async () => {
  const file = path.join(distDir, 'cutroute.html');
  assert.ok(fs.existsSync(file), `no ${file}: run scripts/build-release.sh`);
  // One file: nothing beside it is fetched (a copy alone in an empty folder).
  const alone = fs.mkdtempSync(path.join(fs.realpathSync('/tmp'), 'cutroute-usb-'));
  fs.copyFileSync(file, path.join(alone, 'cutroute.html'));
  const browser = await launchBrowser();
  try {
    const page = await browser.newPage();
    const errors = watchErrors(page);
    const requests = [];
    page.on('request', (r) => { if (!/^(data|blob):/.test(r.url())) requests.push(r.url()); });
    await page.goto(pathToFileURL(path.join(alone, 'cutroute.html')).href);
    // The default sample is drawn from the bytes the page carries.
    await page.waitForFunction(() => document.querySelector('#file-name')?.textContent.includes('E1X_6_01'), null, { timeout: 30000 });
    assert.equal(await page.locator('#nest-view path.part').count(), 8);
    // ccp solves in the worker the page carries.
    await page.selectOption('#solver', 'nearest');
    await page.click('#start');
    await page.waitForFunction(() => document.querySelector('#job-status')?.textContent === 'finished', null, { timeout: 30000 });
    const nearest = cli('solve', 'data/nests/dbs-json/E1X_6_01.dbs.json', '--solver', 'nearest', '--json');
    assert.equal(Number(await page.textContent('#pierces')), nearest.pierces);
    assertRounded(await page.getAttribute('#idle-length', 'data-mm'), nearest.idle_length, 3, 'idle (nearest)');
    await page.selectOption('#solver', 'ccp');
    await page.fill('#time-limit', '1');
    await page.dispatchEvent('#time-limit', 'change');
    await page.click('#start');
    await page.waitForFunction(() => document.querySelector('#job-status')?.textContent === 'finished', null, { timeout: 30000 });
    assert.equal(Number(await page.textContent('#pierces')), 16);
    // A local file opens through the picker.
    await page.setInputFiles('#file-input', path.join(projectRoot, 'data/nests/dbs/seven.dbs'));
    await page.waitForFunction(() => document.querySelector('#file-name')?.textContent.includes('seven'), null, { timeout: 30000 });
    const seven = cli('inspect', 'data/nests/dbs/seven.dbs', '--json');
    assert.equal(await page.locator('#nest-view path.part').count(), seven.parts - 1, 'the parts of seven.dbs (its sheet apart)');
    // Nothing but the page itself was requested.
    assert.deepEqual(requests.filter((u) => !u.endsWith('/cutroute.html')), []);
    assert.deepEqual(errors, []);
  } finally {
    await browser.close();
    fs.rmSync(alone, { recursive: true, force: true });
  }
});
