// Makes the README's screenshots (docs/screenshots/) from the release build, through the e2e
// harness: light and dark themes, the Russian UI, the bounds chart converging (CCP-Relax on
// nested.dbs) and an animation frame. Run by scripts/screenshots.sh; not a test.
import fs from 'node:fs';
import path from 'node:path';
import { startServer, launchBrowser, projectRoot } from './harness.mjs';

const out = path.join(projectRoot, 'docs', 'screenshots');
fs.mkdirSync(out, { recursive: true });
const { server, baseUrl } = await startServer();
const browser = await launchBrowser();

async function page(theme, lang) {
  const context = await browser.newContext({ viewport: { width: 1280, height: 720 }, locale: lang === 'ru' ? 'ru-RU' : 'en-GB' });
  await context.addInitScript(([t, l]) => {
    localStorage.setItem('cutroute.theme', t);
    localStorage.setItem('cutroute.lang', l);
  }, [theme, lang]);
  const p = await context.newPage();
  // 6 s: the CCP bound's first relaxation stage (4,535 mm on nested.dbs) ends after ~1.9 s of a
  // loaded native run and ~3 s in wasm, so a 3 s run would show only its early root bounds.
  await p.goto(`${baseUrl}?sample=nested.dbs&solver=ccp&time=6`);
  await p.waitForFunction(() => document.querySelector('#file-name')?.textContent.includes('nested'), null, { timeout: 20000 });
  return { context, p };
}

async function solve(p) {
  // Start is disabled while the job runs (the status text is in the UI's language).
  await p.click('#start');
  await p.waitForFunction(() => !document.querySelector('#start').disabled, null, { timeout: 30000 });
}

async function shoot(target, name) {
  const file = path.join(out, name);
  await target.screenshot({ path: file });
  console.log(`${file}: ${fs.statSync(file).size} bytes`);
}

try {
  for (const [theme, lang, name] of [['light', 'en', 'light.png'], ['dark', 'en', 'dark.png'], ['light', 'ru', 'russian.png']]) {
    const { context, p } = await page(theme, lang);
    await solve(p);
    await shoot(p, name);
    if (name === 'light.png') {
      await shoot(p.locator('.chart'), 'chart.png');
      // An animation frame: the head 40 % of the way along the route (machine time), the
      // travelled part drawn over the plan.
      const total = Number(await p.getAttribute('#anim-scrub', 'max'));
      await p.locator('#anim-scrub').fill(String(total * 0.4));
      await p.waitForFunction(() => Number(document.querySelector('#anim-clock').dataset.time) > 0);
      await shoot(p.locator('.view'), 'animation.png');
    }
    await context.close();
  }
} finally {
  await browser.close();
  server.close();
}
