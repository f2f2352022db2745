// The lecture screen (issue 18, items 8, 9, 11): at the projector's 1280×720 and at 1920×1080,
// normal and in presentation mode (key F), the drawing, the bounds chart, the bounds and the gap
// are all on screen without scrolling and the toolbar takes at most two rows; the printed page
// carries the drawing, the numbers, the chart and the legend; the sheet picker of multi-sheet
// T-FLEX projects opens each sheet as the CLI's `--sheet` does; progress is announced politely,
// not on every report.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import path from 'node:path';
import { execFileSync } from 'node:child_process';
import { watchErrors, projectRoot, useApp, screenshot, cliBinary } from './harness.mjs';

const app = useApp(before, after);

function cutroute(...args) {
  const binary = cliBinary();
  return JSON.parse(execFileSync(binary, args, { encoding: 'utf8', maxBuffer: 64 << 20 }));
}

async function solved(page, solver, seconds) {
  await page.selectOption('#solver', solver);
  await page.fill('#time-limit', String(seconds));
  await page.locator('#time-limit').dispatchEvent('change');
  await page.click('#start');
  await page.waitForFunction(() => ['finished', 'cancelled'].includes(document.querySelector('#job-status')?.textContent),
    null, { timeout: 30000 });
}

/** Boxes of what a lecture shows, and whether each lies wholly on screen. */
async function lectureBoxes(page) {
  return page.evaluate(() => {
    const vw = document.documentElement.clientWidth;
    const vh = document.documentElement.clientHeight;
    const panel = document.querySelector('.stats').getBoundingClientRect();
    const seen = {};
    for (const id of ['nest-view', 'bounds-chart', 'upper-bound', 'lower-bound', 'gap']) {
      const r = document.getElementById(id).getBoundingClientRect();
      // Inside the window, and inside the side panel's visible box for what the panel holds.
      const inPanel = id === 'nest-view' || (r.top >= panel.top - 0.5 && r.bottom <= panel.bottom + 0.5);
      seen[id] = { box: [r.x, r.y, r.width, r.height], visible: r.width > 0 && r.height > 0
        && r.left >= -0.5 && r.top >= -0.5 && r.right <= vw + 0.5 && r.bottom <= vh + 0.5 && inPanel };
    }
    // The toolbar's rows: its controls' vertical centres, clustered.
    const centres = [...document.querySelector('.toolbar').children]
      .map((c) => c.getBoundingClientRect()).filter((r) => r.height > 0)
      .map((r) => r.top + r.height / 2).sort((a, b) => a - b);
    let rows = 0; let last = -Infinity;
    for (const c of centres) { if (c - last > 12) rows++; last = c; }
    const axis = document.getElementById('chart-y-label').getBoundingClientRect().height;
    return {
      seen, rows, axis,
      scroll: [document.documentElement.scrollWidth - vw, document.documentElement.scrollHeight - vh],
      panelScroll: document.querySelector('.stats').scrollTop,
    };
  });
}

for (const [width, height] of [[1280, 720], [1920, 1080]]) {
  test(`lecture layout at ${width}×${height}, normal and presentation mode`, async () => {
    const context = await app.browser.newContext({ viewport: { width, height } });
    const page = await context.newPage();
    const errors = watchErrors(page);
    await page.goto(`${app.baseUrl}?sample=nested.dbs`);
    await page.waitForFunction(() => document.querySelector('#file-name')?.textContent.includes('nested'), null, { timeout: 20000 });
    await solved(page, 'ccp', 1.5);
    for (const mode of ['normal', 'presentation']) {
      if (mode === 'presentation') {
        await page.locator('#nest-view').focus();
        await page.keyboard.press('f');
        await page.waitForFunction(() => document.documentElement.hasAttribute('data-presentation'));
      }
      const seen = await lectureBoxes(page);
      for (const [id, { visible, box }] of Object.entries(seen.seen)) {
        assert.ok(visible, `${mode} ${width}×${height}: #${id} on screen without scrolling: ${box}`);
      }
      assert.deepEqual(seen.scroll, [0, 0], `${mode}: the page does not scroll`);
      assert.equal(seen.panelScroll, 0);
      assert.ok(seen.rows <= 2, `${mode} ${width}×${height}: the toolbar takes ${seen.rows} rows`);
      // The chart's text, readable from the back row: at least 11 px, larger when presenting.
      assert.ok(seen.axis >= (mode === 'presentation' ? 16 : 11), `${mode}: chart axis text ${seen.axis} px`);
      assert.ok(seen.seen['bounds-chart'].box[2] >= 200, `chart width ${seen.seen['bounds-chart'].box[2]}`);
      await screenshot(page, `lecture-${width}x${height}-${mode}.png`);
    }
    assert.deepEqual(errors, []);
    await context.close();
  });
}

test('the printed page carries the drawing, the numbers, the chart and the legend', async () => {
  const context = await app.browser.newContext({ viewport: { width: 1280, height: 800 } });
  const page = await context.newPage();
  const errors = watchErrors(page);
  await page.goto(`${app.baseUrl}?sample=nested.dbs`);
  await page.waitForFunction(() => document.querySelector('#file-name')?.textContent.includes('nested'), null, { timeout: 20000 });
  await solved(page, 'ccp', 1);
  const cdp = await context.newCDPSession(page);
  await cdp.send('Emulation.setEmulatedMedia', { media: 'print' });
  assert.equal(await page.evaluate(() => matchMedia('print').matches), true);
  for (const selector of ['#nest-view', '#file-name', '#upper-bound', '#lower-bound', '#gap', '#idle-length', '#pierces',
    '#machine-time', '#bounds-chart', '#drawing-legend', '.legend-ub', '.legend-lb']) {
    assert.ok(await page.locator(selector).isVisible(), `${selector} is printed`);
  }
  for (const selector of ['.toolbar', '.solver-panel', '.animation', '#start', '#profiles']) {
    assert.equal(await page.locator(selector).isVisible(), false, `${selector} is not printed`);
  }
  // The numbers printed are the page's.
  assert.match(await page.textContent('#gap'), /%/);
  // The drawing is not cut off: it keeps its aspect ratio at the page's width.
  const drawing = await page.locator('#nest-view').boundingBox();
  assert.ok(drawing.height > 100 && drawing.width > 500, JSON.stringify(drawing));
  const pdf = await page.pdf({ format: 'A4' });
  assert.ok(pdf.length > 10_000, `a PDF of ${pdf.length} bytes`);
  await screenshot(page, 'print.png');
  assert.deepEqual(errors, []);
  await context.close();
});

test('a multi-sheet T-FLEX project: the sheet picker opens each sheet as the CLI --sheet does', async () => {
  const file = path.join(projectRoot, 'data', 'nests', 'tflex-multi', 'two-sheets.tfnesting');
  const context = await app.browser.newContext({ viewport: { width: 1280, height: 800 } });
  const page = await context.newPage();
  const errors = watchErrors(page);
  await page.goto(app.baseUrl);
  await page.waitForFunction(() => document.querySelector('#file-name')?.textContent.includes('E1X_6_01'), null, { timeout: 20000 });
  assert.equal(await page.locator('#sheet').count(), 0, 'no picker for a one-sheet file');
  await page.setInputFiles('#file-input', file);
  await page.waitForFunction(() => document.querySelector('#file-name')?.textContent.includes('two-sheets'));
  const sheets = cutroute('inspect', file, '--json').sheets;
  assert.equal(await page.locator('#sheet option').count(), sheets.length);
  for (let k = 0; k < sheets.length; k++) {
    if (k > 0) {
      await page.selectOption('#sheet', String(k));
      await page.waitForFunction((v) => document.querySelector('#sheet')?.value === v, String(k));
    }
    const expected = cutroute('inspect', file, '--json', '--sheet', String(k + 1));
    const drawn = await page.locator('#nest-view path.part').count();
    const sheetDrawn = (await page.getAttribute('#nest-view path.sheet', 'd'))?.length > 0 ? 1 : 0;
    assert.equal(drawn + sheetDrawn, expected.parts, `sheet ${k + 1}: parts`);
    await page.selectOption('#solver', 'nearest');
    await page.click('#start');
    await page.waitForFunction(() => document.querySelector('#job-status')?.textContent === 'finished', null, { timeout: 20000 });
    const route = cutroute('solve', file, '--sheet', String(k + 1), '--solver', 'nearest', '--json');
    assert.equal(Number(await page.textContent('#pierces')), route.pierces, `sheet ${k + 1}: pierces`);
    assertClose(Number(await page.getAttribute('#idle-length', 'data-mm')), route.idle_length, `sheet ${k + 1}: idle`);
  }
  assert.deepEqual(errors, []);
  await context.close();
});

function assertClose(a, b, what) {
  assert.ok(Math.abs(a - b) <= 1e-3 * Math.max(1, Math.abs(b)), `${what}: ${a} vs ${b}`);
}

test('progress is announced politely, on phase changes and improvements, not on every report', async () => {
  const context = await app.browser.newContext({ viewport: { width: 1280, height: 800 } });
  const page = await context.newPage();
  const errors = watchErrors(page);
  await page.goto(`${app.baseUrl}?sample=nested.dbs`);
  await page.waitForFunction(() => document.querySelector('#file-name')?.textContent.includes('nested'), null, { timeout: 20000 });
  const region = page.locator('#progress-announcer');
  assert.equal(await region.getAttribute('aria-live'), 'polite');
  assert.equal(await region.getAttribute('role'), 'status');
  await page.evaluate(() => {
    window.announced = [];
    window.reports = 0;
    new MutationObserver(() => window.announced.push(document.querySelector('#progress-announcer').textContent))
      .observe(document.querySelector('#progress-announcer'), { childList: true, characterData: true, subtree: true });
    new MutationObserver(() => window.reports++)
      .observe(document.querySelector('#elapsed'), { childList: true, characterData: true, subtree: true });
  });
  await solved(page, 'ccp', 3);
  const { announced, reports } = await page.evaluate(() => ({ announced: window.announced, reports: window.reports }));
  assert.ok(announced.length >= 1, 'something was said');
  assert.ok(reports > 3 * announced.length, `${announced.length} announcements for ${reports} reports`);
  const last = announced.at(-1);
  assert.match(last, /upper bound/);
  const upper = await page.textContent('#upper-bound');
  assert.ok(announced.some((a) => a.includes(upper)), `the final upper bound ${upper} was said: ${announced.join(' | ')}`);
  assert.deepEqual(errors, []);
  await context.close();
});
