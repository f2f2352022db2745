// Issue 18, item 1: a browser whose language is Russian gets the Russian UI with no English UI
// text left; the switch goes to English and back and is remembered across reloads; a reader's
// error is worded in Russian with its location, and in English it is the CLI's text.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { startServer, launchBrowser, watchErrors, projectRoot, cliError, screenshot, screenshotDir } from './harness.mjs';

let server;
let baseUrl;
let browser;
before(async () => {
  ({ server, baseUrl } = await startServer());
  browser = await launchBrowser({ lang: 'ru-RU' });
  fs.mkdirSync(screenshotDir, { recursive: true });
});
after(async () => {
  await browser?.close();
  server?.close();
});

// Latin words the Russian UI may show: proper names (the program, formats, solvers, their
// algorithms, RouteManager), solver ids, the language's own name in the switch, and `exp` in
// the formula of H. File names, part names «…» and G-code words are taken out before.
const ALLOWED = new Set([
  'cutroute', 'English', 'CCP', 'Relax', 'ALNS', 'SCCP', 'GSCCP', 'AOE', 'VNS', 'PCGTSP',
  'PCGLNS', 'PCGTSPLIB', 'DBS', 'JSON', 'SVG', 'HTML', 'DXF', 'RouteManager', 'nearest', 'ccp',
  'chain', 'heuristic', 'exact', 'exp',
  // Controllers the G-code presets are named for.
  'GRBL', 'LinuxCNC', 'QtPlasmaC', 'Mach', 'Fanuc',
]);

/** Every Latin word of the page's text nodes and title/aria-label/placeholder attributes that
 * is not an allowed name, with where it was found. */
async function englishLeft(page) {
  const found = await page.evaluate(() => {
    const texts = [];
    const walker = document.createTreeWalker(document.body, NodeFilter.SHOW_TEXT);
    for (let n = walker.nextNode(); n; n = walker.nextNode()) {
      const parent = n.parentElement;
      if (!parent || parent.closest('script, style, noscript')) continue;
      texts.push([n.textContent, parent.id || parent.tagName]);
    }
    for (const el of document.body.querySelectorAll('*')) {
      for (const attr of ['title', 'aria-label', 'placeholder']) {
        const v = el.getAttribute(attr);
        if (v) texts.push([v, `${el.id || el.tagName}[${attr}]`]);
      }
    }
    texts.push([document.title, 'title']);
    return texts;
  });
  const left = [];
  for (const [text, where] of found) {
    // Names from the file (parts «…», files), G-code words (G02, M03, I, J) and the CLI's flags
    // (--profile) are not UI text.
    const cleaned = text
      .replace(/--[a-z][a-z-]*/g, ' ')
      .replace(/«[^»]*»/g, ' ')
      .replace(/[\w.-]+\.(dbs|json|dxf|nc|svg|html|pcglns|tfnesting)\b/gi, ' ')
      .replace(/\b(E1X_6_01|test1|nested|seven)\b/g, ' ')
      .replace(/\b[GM]\d+\b/g, ' ');
    for (const word of cleaned.match(/[A-Za-z]{2,}/g) ?? []) {
      if (!ALLOWED.has(word)) left.push(`${word} in ${JSON.stringify(text)} (${where})`);
    }
  }
  return left;
}

async function fileShown(page, name) {
  await page.waitForFunction((n) => (document.querySelector('#file-name')?.textContent ?? '').includes(n),
    name, { timeout: 30000 });
}

const status = (page, wanted, timeout = 60000) => page.waitForFunction(
  (w) => new RegExp(w).test(document.querySelector('#job-status')?.textContent ?? ''), wanted.source, { timeout });

async function solve(page, solver, seconds) {
  await page.selectOption('#solver', solver);
  await page.fill('#time-limit', String(seconds));
  await page.dispatchEvent('#time-limit', 'change');
  await page.click('#start');
}

test('a Russian browser gets the Russian UI, with no English UI text left', async () => {
  const context = await browser.newContext({ locale: 'ru-RU', viewport: { width: 1280, height: 800 } });
  const page = await context.newPage();
  const errors = watchErrors(page);
  await page.goto(baseUrl);
  await fileShown(page, 'E1X_6_01');
  assert.equal(await page.evaluate(() => document.documentElement.lang), 'ru');
  assert.match(await page.title(), /маршруты резки/);
  assert.equal(await page.inputValue('#language'), 'ru');
  // A job run to its end fills the stats, the phase, the chart and the animation bar.
  await solve(page, 'ccp', 1);
  await status(page, /^завершено$/);
  assert.match(await page.textContent('#phase'), /[а-я]/, 'the phase is worded in Russian');
  assert.match(await page.textContent('#idle-length'), /^\d+\.\d мм$/);
  assert.match(await page.textContent('#elapsed'), /^\d+\.\d\d с$/);
  assert.match(await page.textContent('#chart-range'), / за [\d.]+ с$/);
  assert.match(await page.textContent('.stats'), /Верхняя оценка/);
  assert.match(await page.textContent('.stats'), /Нижняя оценка/);
  assert.match(await page.textContent('.stats'), /Разрыв/);
  // Kept results fill the compare table; the export and machine panels open.
  await page.click('#keep-result');
  await page.click('.export summary');
  assert.deepEqual(await englishLeft(page), []);
  await screenshot(page, 'i18n-ru.png');
  // The exact solver builds its model row by row: the phase names it with rows done of all,
  // and a progress bar shows how far it is (nested.dbs at 25 mm builds for seconds).
  await page.setInputFiles('#file-input', path.join(projectRoot, 'data', 'nests', 'dbs', 'nested.dbs'));
  await fileShown(page, 'nested.dbs (DBS, двоичный)');
  await page.fill('#step', '25');
  await page.dispatchEvent('#step', 'change');
  await solve(page, 'exact', 60);
  await page.waitForFunction(() => document.querySelector('#job-status')?.textContent === 'выполняется'
    && /^построение модели: \d+ из \d+ строк матрицы стоимостей/.test(document.querySelector('#phase')?.textContent ?? ''),
  null, { timeout: 20000 });
  const bar = await page.evaluate(() => {
    const p = document.querySelector('#phase-progress');
    return p && { max: p.max, value: p.value };
  });
  assert.ok(bar && bar.max > 1 && bar.value <= bar.max, `a progress bar for the rows: ${JSON.stringify(bar)}`);
  const [, done, total] = (await page.textContent('#phase')).match(/(\d+) из (\d+)/);
  assert.ok(Number(done) <= Number(total));
  assert.deepEqual(await englishLeft(page), []);
  await page.click('#stop');
  await status(page, /^отменено$/);
  assert.deepEqual(errors, []);
  await context.close();
});

test('the switch goes to English and back, and is remembered across reloads', async () => {
  const context = await browser.newContext({ locale: 'ru-RU', viewport: { width: 1280, height: 800 } });
  const page = await context.newPage();
  const errors = watchErrors(page);
  await page.goto(baseUrl);
  await fileShown(page, 'E1X_6_01');
  assert.equal(await page.textContent('#start'), 'Пуск');
  await page.selectOption('#language', 'en');
  await page.waitForFunction(() => document.documentElement.lang === 'en');
  assert.equal(await page.textContent('#start'), 'Start');
  assert.equal(await page.textContent('#job-status'), 'idle');
  assert.match(await page.title(), /tool paths for CNC sheet cutting/);
  await page.reload();
  await fileShown(page, 'E1X_6_01');
  assert.equal(await page.evaluate(() => document.documentElement.lang), 'en', 'English is remembered');
  assert.equal(await page.textContent('#start'), 'Start');
  await page.selectOption('#language', 'ru');
  await page.waitForFunction(() => document.documentElement.lang === 'ru');
  assert.equal(await page.textContent('#start'), 'Пуск');
  await page.reload();
  await fileShown(page, 'E1X_6_01');
  assert.equal(await page.textContent('#start'), 'Пуск', 'Russian is remembered');
  assert.equal(await page.textContent('#job-status'), 'ожидание');
  assert.deepEqual(errors, []);
  await context.close();
});

test('a reader error is worded in Russian with its location, and is the CLI\'s text in English', async () => {
  const context = await browser.newContext({ locale: 'ru-RU', viewport: { width: 1280, height: 800 } });
  const page = await context.newPage();
  const errors = watchErrors(page);
  await page.goto(baseUrl);
  await fileShown(page, 'E1X_6_01');
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'cutroute-i18n-'));
  const truncated = path.join(dir, 'nested_truncated.dbs');
  fs.writeFileSync(truncated, fs.readFileSync(path.join(projectRoot, 'data', 'nests', 'dbs', 'nested.dbs')).subarray(0, 700));
  await page.setInputFiles('#file-input', truncated);
  const alert = page.locator('.error[role=alert]');
  await alert.waitFor({ timeout: 30000 });
  const russian = await alert.textContent();
  assert.match(russian, /^nested_truncated\.dbs \(DBS, двоичный\): файл не читается: байт 696: /);
  const oracle = cliError(truncated, 'inspect', truncated);
  await page.selectOption('#language', 'en');
  await page.waitForFunction((m) => document.querySelector('.error[role=alert]')?.textContent === m, oracle.message,
    { timeout: 5000 }).catch(() => {});
  assert.equal(await alert.textContent(), oracle.message, 'in English the page shows the CLI\'s words');
  await page.selectOption('#language', 'ru');
  assert.equal(await alert.textContent(), russian);
  // A JSON file that does not parse: line and column in Russian.
  const broken = path.join(dir, 'broken.json');
  fs.writeFileSync(broken, '{\n  "a": [1, 2,\n');
  await page.setInputFiles('#file-input', broken);
  await page.waitForFunction(() => /broken\.json/.test(document.querySelector('.error[role=alert]')?.textContent ?? ''),
    null, { timeout: 30000 });
  assert.match(await alert.textContent(), /^broken\.json \(JSON\): ошибка в JSON: строка \d+, столбец \d+: /);
  fs.rmSync(dir, { recursive: true, force: true });
  assert.deepEqual(errors, []);
  await context.close();
});
