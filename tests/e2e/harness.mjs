// Shared by the end-to-end tests: a static file server for the release build (mounted under a
// sub-path, as on a static host) and the system's headless Chromium.
import http from 'node:http';
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { execFileSync, spawnSync } from 'node:child_process';
import { chromium } from 'playwright-core';

const here = path.dirname(fileURLToPath(import.meta.url));
export const projectRoot = path.resolve(here, '..', '..');
export const distDir = process.env.CUTROUTE_DIST ?? path.join(projectRoot, 'dist');
export const screenshotDir = path.join(projectRoot, 'target', 'e2e');
export const SUB_PATH = '/cutroute/';

const MIME = {
  '.html': 'text/html; charset=utf-8', '.js': 'text/javascript', '.wasm': 'application/wasm',
  '.css': 'text/css', '.json': 'application/json', '.svg': 'image/svg+xml', '.png': 'image/png',
};

/** Serves `distDir` under SUB_PATH on a free loopback port; resolves to { server, baseUrl }. */
export async function startServer() {
  if (!fs.existsSync(path.join(distDir, 'index.html'))) {
    throw new Error(`no release build at ${distDir}: run scripts/build-release.sh first`);
  }
  const server = http.createServer((req, res) => {
    const url = new URL(req.url, 'http://localhost');
    if (!url.pathname.startsWith(SUB_PATH)) { res.writeHead(404); res.end('outside the app'); return; }
    let rel = decodeURIComponent(url.pathname.slice(SUB_PATH.length)) || 'index.html';
    const file = path.resolve(distDir, rel);
    if (!file.startsWith(path.resolve(distDir))) { res.writeHead(403); res.end(); return; }
    fs.readFile(file, (err, data) => {
      if (err) { res.writeHead(404); res.end('not found'); return; }
      res.writeHead(200, { 'content-type': MIME[path.extname(file)] ?? 'application/octet-stream' });
      res.end(data);
    });
  });
  await new Promise((resolve) => server.listen(0, '127.0.0.1', resolve));
  const { port } = server.address();
  return { server, baseUrl: `http://127.0.0.1:${port}${SUB_PATH}` };
}

/**
 * The Debian Chromium, headless, with the flags this closed network needs. The browser's
 * language is English unless `lang` says otherwise: the page follows the browser's language
 * (src/i18n.rs) and the tests assert English texts, whatever the machine's locale.
 */
export async function launchBrowser({ lang = 'en-US' } = {}) {
  return chromium.launch({
    executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium',
    headless: true,
    args: ['--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
      '--disable-background-networking', '--disable-component-update', '--disable-sync',
      `--lang=${lang}`, `--accept-lang=${lang}`],
  });
}

/** Collects page errors so a test can assert the app never threw. */
export function watchErrors(page) {
  const errors = [];
  page.on('pageerror', (e) => errors.push(String(e)));
  page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
  page.on('response', (r) => { if (r.status() >= 400) errors.push(`HTTP ${r.status()} ${r.url()}`); });
  return errors;
}

/**
 * Registers before/after hooks that serve the release build and start Chromium for the tests of
 * one file; returns an object whose `baseUrl` and `browser` are set once the hooks have run.
 */
export function useApp(before, after) {
  const app = { baseUrl: undefined, browser: undefined, server: undefined };
  before(async () => {
    ({ server: app.server, baseUrl: app.baseUrl } = await startServer());
    app.browser = await launchBrowser();
    fs.mkdirSync(screenshotDir, { recursive: true });
  });
  after(async () => {
    await app.browser?.close();
    app.server?.close();
  });
  return app;
}

/**
 * Saves a screenshot of the page under `target/e2e/` and fails unless it shows something: the
 * PNG is decoded in the browser and must have several colours, none covering almost all of it.
 */
export async function screenshot(page, name) {
  const file = path.join(screenshotDir, name);
  const png = await page.screenshot({ path: file });
  const seen = await page.evaluate(async (b64) => {
    const img = new Image();
    img.src = `data:image/png;base64,${b64}`;
    await img.decode();
    const canvas = new OffscreenCanvas(img.width, img.height);
    const g = canvas.getContext('2d');
    g.drawImage(img, 0, 0);
    const data = g.getImageData(0, 0, img.width, img.height).data;
    const counts = new Map();
    let samples = 0;
    // Every 7th pixel: enough to see the drawing, cheap at 1920×1080.
    for (let i = 0; i < data.length; i += 4 * 7) {
      const key = (data[i] << 16) | (data[i + 1] << 8) | data[i + 2];
      counts.set(key, (counts.get(key) ?? 0) + 1);
      samples++;
    }
    return { colours: counts.size, largestShare: Math.max(...counts.values()) / samples };
  }, png.toString('base64'));
  if (seen.colours < 8 || seen.largestShare > 0.97) {
    throw new Error(`screenshot ${file} looks blank: ${JSON.stringify(seen)}`);
  }
  return file;
}

/**
 * The oracle outside the page: runs the native `cutroute` CLI (built on first use) with `args`
 * and returns its JSON report. e2e tests compare what the page shows with it.
 */
export function cli(...args) {
  const out = execFileSync(cliBinary(), args, { cwd: projectRoot, encoding: 'utf8', maxBuffer: 64 << 20 });
  return JSON.parse(out);
}
let cliBuilt = false;

export function cliBinary() {
  if (!cliBuilt) {
    execFileSync('cargo', ['build', '--quiet', '-p', 'cutroute-cli'], { cwd: projectRoot, stdio: 'inherit' });
    cliBuilt = true;
  }
  return path.join(projectRoot, 'target', 'debug', 'cutroute');
}

/**
 * The oracle for a refusal: runs the CLI with `args`, which must fail, and returns its exit
 * status and its error (the last line of stderr) without the `cutroute: ` prefix. The engine names a file as it was
 * given; `file` (a path among `args`) is replaced by its base name, as the page names it.
 */
export function cliError(file, ...args) {
  const run = spawnSync(cliBinary(), args, { cwd: projectRoot, encoding: 'utf8', maxBuffer: 64 << 20 });
  if (run.status === 0) throw new Error(`cutroute ${args.join(' ')} succeeded; a refusal was expected`);
  // Text mode prints progress lines first; the error is the last line.
  const last = run.stderr.trim().split('\n').at(-1);
  const message = last.replace(/^cutroute: /, '').split(file).join(path.basename(file));
  return { status: run.status, message };
}

/**
 * Display rounding of the page's figures: `shown` (the page's text, `decimals` places) must be
 * `exact` rounded, i.e. within half a unit of the last place shown.
 */
export function assertRounded(shown, exact, decimals, what) {
  const value = Number(String(shown).replace(/[^0-9eE.+-]/g, ''));
  const half = 0.5 * 10 ** -decimals;
  if (!Number.isFinite(value) || !(Math.abs(value - exact) <= half + 1e-9 * Math.abs(exact))) {
    throw new Error(`${what}: the page shows ${shown}, the oracle ${exact} (±${half})`);
  }
}

/**
 * Selects `solver`, sets the time limit and runs the job to its end in the page; fails with the
 * job's status unless it finishes.
 */
export async function runSolver(page, solver, seconds) {
  await page.selectOption('#solver', solver);
  await page.fill('#time-limit', String(seconds));
  await page.dispatchEvent('#time-limit', 'change');
  await page.click('#start');
  await page.waitForFunction(() => /^(finished|failed)/.test(document.querySelector('#job-status')?.textContent ?? ''),
    null, { timeout: 120000 });
  const status = await page.textContent('#job-status');
  if (status !== 'finished') throw new Error(`${solver}: the job ended ${status}`);
}

/**
 * Sets a number field of the page (an `<input type=number>` read on change) to `value`.
 */
export async function setNumber(page, selector, value) {
  await page.fill(selector, String(value));
  await page.dispatchEvent(selector, 'change');
}

/**
 * Moves the animation to machine time `t` (the scrub slider) and returns what the heat-map
 * layer draws then: its time, hottest and summed cell temperatures, and the cells per colour
 * level. Fails when the layer is missing.
 */
/**
 * The heat field an oracle expects where the page drew `frame` (from `heatMapAt`): the model of
 * issue #19 recomputed from a CLI report's pierce points and machine times (`route[].pierce`,
 * `route[].t`): T(p, t) = Σ over sources switched on by t of exp(−|p − M|²/2σ² − (t − t_M)/τ),
 * kernels below exp(−40) left out as the model does; sampled at the cell centres of the page's
 * grid. Returns the sum, the maximum and the cells per colour level.
 */
export function expectedHeatField(report, frame, sigma, tau) {
  const [x0, y0, x1, y1, across] = frame.grid;
  const side = Math.max(x1 - x0, y1 - y0) / across;
  const [nx, ny] = [Math.max(1, Math.ceil((x1 - x0) / side)), Math.max(1, Math.ceil((y1 - y0) / side))];
  const sources = report.route.filter((s) => s.t <= frame.time);
  const cells = new Array(frame.thresholds.length).fill(0);
  let sum = 0;
  let max = 0;
  for (let j = 0; j < ny; j++) {
    for (let i = 0; i < nx; i++) {
      const [cx, cy] = [x0 + i * side + side / 2, y0 + j * side + side / 2];
      let temperature = 0;
      for (let k = sources.length - 1; k >= 0; k--) {
        const dt = (frame.time - sources[k].t) / tau;
        if (dt > 40) break;
        const [dx, dy] = [cx - sources[k].pierce[0], cy - sources[k].pierce[1]];
        const exponent = (dx * dx + dy * dy) * (0.5 / (sigma * sigma)) + dt;
        if (exponent <= 40) temperature += Math.exp(-exponent);
      }
      sum += temperature;
      max = Math.max(max, temperature);
      let level = -1;
      frame.thresholds.forEach((l, k) => { if (temperature >= l) level = k; });
      if (level >= 0) cells[level] += 1;
    }
  }
  return { sum, max, cells };
}

export async function heatMapAt(page, t) {
  await page.locator('#anim-scrub').fill(String(t));
  await page.waitForFunction((want) => {
    const g = document.querySelector('#heat-map');
    return g && Math.abs(Number(g.getAttribute('data-time')) - want) < 1e-2;
  }, t, { timeout: 10000 });
  return page.evaluate(() => {
    const g = document.querySelector('#heat-map');
    return {
      time: Number(g.getAttribute('data-time')),
      grid: g.getAttribute('data-grid').split(' ').map(Number),
      thresholds: g.getAttribute('data-levels').split(' ').map(Number),
      max: Number(g.getAttribute('data-max')),
      sum: Number(g.getAttribute('data-sum')),
      levels: [...g.querySelectorAll('path.heat')].map((p) => [p.getAttribute('class'), Number(p.getAttribute('data-cells'))]),
    };
  });
}
