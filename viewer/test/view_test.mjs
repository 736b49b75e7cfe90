// The viewer in a real headless browser (Debian's chromium, driven by puppeteer-core): the page
// loads without console errors, WebGL draws the meshes, the contacts drawn at each step are the
// step's contacts as `caliber run --contacts` wrote them, and moving the slider with the keyboard
// changes them. Optionally saves a screenshot.
//
// usage: node view_test.mjs PAGE.html CONTACTS.jsonl [--screenshot OUT.png] [--step K]
//        (chromium from $CALIBER_CHROMIUM, else /usr/bin/chromium)

import fs from 'node:fs';
import path from 'node:path';
import { pathToFileURL } from 'node:url';
import puppeteer from 'puppeteer-core';

const args = process.argv.slice(2);
const option = (name) => {
  const i = args.indexOf(name);
  return i >= 0 ? args[i + 1] : undefined;
};
const [pagePath, contactsPath] = args;
if (!pagePath || !contactsPath) {
  console.error('usage: node view_test.mjs PAGE.html CONTACTS.jsonl [--screenshot OUT.png] [--step K]');
  process.exit(2);
}
const chromium = process.env.CALIBER_CHROMIUM || '/usr/bin/chromium';
if (!fs.existsSync(chromium)) {
  console.error(`view_test: no chromium at ${chromium} (scripts/setup.sh installs Debian's chromium)`);
  process.exit(1);
}
const expected = fs.readFileSync(contactsPath, 'utf8').trim().split('\n').map((l) => JSON.parse(l).contacts.length);

let failures = 0;
function check(ok, what) {
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${what}`);
  if (!ok) ++failures;
}

const browser = await puppeteer.launch({
  executablePath: chromium,
  headless: true,
  args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--window-size=1280,800'],
  defaultViewport: { width: 1280, height: 800 },
});
try {
  const page = await browser.newPage();
  const errors = [];
  page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
  page.on('pageerror', (e) => errors.push(String(e)));
  page.on('requestfailed', (r) => errors.push(`request failed: ${r.url()}`));
  const requests = [];
  page.on('request', (r) => requests.push(r.url()));
  await page.goto(pathToFileURL(path.resolve(pagePath)).href, { waitUntil: 'load' });
  await page.waitForFunction(() => window.caliberView?.state.ready, { timeout: 60000 });

  const drawn = () => page.evaluate(() => {
    const cloud = window.caliberView.scene.getObjectByName('contacts');
    return { step: window.caliberView.state.step, points: cloud.geometry.getAttribute('position').count,
             boxes: window.caliberView.state.drawnTaskBoxes };
  });
  const steps = await page.evaluate(() => window.caliberView.data.steps.length);
  check(steps === expected.length, `the page holds ${steps} steps, caliber run wrote ${expected.length}`);
  const first = await drawn();
  check(first.step === 0 && first.points === expected[0], `step 0 draws ${first.points} contacts, expected ${expected[0]}`);
  const covered = await page.evaluate(() => window.caliberView.coveredFraction());
  check(covered > 0.02, `WebGL drew the meshes (${(100 * covered).toFixed(1)} % of the canvas is not background)`);

  // The slider, moved as a user would: focused, then the arrow key, one step at a time.
  const target = expected.findIndex((n) => n !== expected[0]);
  check(target > 0, `some step's contact count differs from step 0's (step ${target})`);
  await page.focus('#step');
  let boxes = first.boxes;
  for (let k = 1; k <= Math.max(target, 0); ++k) {
    await page.keyboard.press('ArrowRight');
    const now = await drawn();
    boxes = Math.max(boxes, now.boxes);
    check(now.step === k && now.points === expected[k], `after ${k} x ArrowRight: step ${now.step} draws ${now.points} contacts, expected ${expected[k]}`);
  }
  const method = await page.evaluate(() => window.caliberView.data.method);
  if (['aposteriori', 'apriori', 'hybrid'].includes(method)) check(boxes > 0, `run-time task boxes drawn (${boxes})`);

  const shot = option('--screenshot');
  if (shot) {
    const k = Number(option('--step') ?? 0);
    await page.evaluate((s) => { document.getElementById('step').value = String(s); window.caliberView.showStep(s); }, k);
    await page.click('#frame-heaviest');  // framed at that step's poses
    await page.screenshot({ path: shot });
    console.log(`screenshot of step ${k}: ${shot}`);
  }
  const remote = requests.filter((u) => !u.startsWith('file:') && !u.startsWith('data:'));
  check(remote.length === 0, `no network requests (${remote.join(', ') || 'none'})`);
  check(errors.length === 0, `no console errors${errors.length ? ': ' + errors.join(' | ') : ''}`);
} finally {
  await browser.close();
}
process.exit(failures ? 1 : 0);
