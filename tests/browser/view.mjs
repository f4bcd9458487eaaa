// `btfsm view` pages driven in a real browser (headless Chromium, through
// puppeteer-core; docs/view.md). For every scenario and log given, the page
// is loaded and driven like a user would: arrow keys, the next / prev
// buttons, a click on the slider, the divergence buttons, End and Home. At
// each step reached, every node's computed fill in every panel must equal
// the fill of the same node (by its SVG <title>) in an independent drawing
// of that step: `btfsm dot FILE --trace T --step K --policy NAME` for a
// scenario (its trace written by `btfsm sim --trace`), `btfsm log dot LOG
// --step K+1` for a log, rendered by Graphviz with the statuses as DOT
// fills, and read by the same browser. Some node must change fill between
// the steps checked. The page must make no request (it is self-contained)
// and print no error. On a scenario's page, each robot on the room map must
// have moved from step 0 as the trace's run did (100 px a metre).
// --scale FILE measures the page of a long run: its
// size, load time and the time to jump to the last step (printed).
// Screenshots go to OUT (and, with --screenshots DIR, the first scenario's
// to DIR, for the README).
// Usage: node view.mjs --btfsm BIN --out DIR [--chromium PATH]
//          [--screenshots DIR] [--scale FILE] [--log LOG]... SCENARIO...
import puppeteer from 'puppeteer-core';
import { execFileSync } from 'node:child_process';
import { mkdirSync, readFileSync, statSync, existsSync, copyFileSync } from 'node:fs';
import { basename, join, resolve } from 'node:path';
import { pathToFileURL } from 'node:url';

const args = process.argv.slice(2);
const opt = { logs: [], scenarios: [] };
for (let i = 0; i < args.length; i++) {
  const a = args[i];
  if (a === '--btfsm') opt.btfsm = args[++i];
  else if (a === '--out') opt.out = args[++i];
  else if (a === '--chromium') opt.chromium = args[++i];
  else if (a === '--screenshots') opt.shots = args[++i];
  else if (a === '--scale') opt.scale = args[++i];
  else if (a === '--log') opt.logs.push(args[++i]);
  else opt.scenarios.push(a);
}
const chromium = opt.chromium || ['/usr/bin/chromium', '/usr/bin/chromium-browser', '/usr/bin/google-chrome']
  .find((p) => existsSync(p));
if (!opt.btfsm || !opt.out || !chromium) {
  console.error('usage: node view.mjs --btfsm BIN --out DIR [--chromium PATH] ... (no Chromium found: apt-get install chromium)');
  process.exit(2);
}
mkdirSync(opt.out, { recursive: true });
const run = (argv, okCodes = [0]) => {
  try {
    return execFileSync(opt.btfsm, argv, { encoding: 'utf8', stdio: ['ignore', 'pipe', 'pipe'], maxBuffer: 1 << 28 });
  } catch (e) {
    if (okCodes.includes(e.status)) return e.stdout;
    throw new Error(`btfsm ${argv.join(' ')} exited ${e.status}: ${e.stderr}`);
  }
};

const browser = await puppeteer.launch({
  executablePath: chromium,
  headless: true,
  args: ['--no-sandbox', '--disable-gpu', '--allow-file-access-from-files'],
  defaultViewport: { width: 1500, height: 1000 },
});
let failed = 0;
const fail = (m) => { console.error('FAIL ' + m); failed++; };

// Title -> computed fills of every shape of every node of an SVG.
const fillsIn = (root) => {
  const out = {};
  for (const g of root.querySelectorAll('g.node')) {
    const t = g.querySelector('title');
    // `dot --trace` adds a legend of the status fills (nodes `legend: ...`),
    // which is not a vertex: the page has its own legend.
    if (!t || t.textContent.startsWith('legend: ')) continue;
    out[t.textContent] = [...g.querySelectorAll('ellipse, polygon, path')].map((s) => getComputedStyle(s).fill).join(' ');
  }
  return out;
};

const oraclePage = await browser.newPage();
const oracleCache = new Map();
async function oracleFills(argv) {
  const key = argv.join('\0');
  if (!oracleCache.has(key)) {
    const svg = run([...argv, '--render', 'svg']);
    const body = svg.slice(svg.indexOf('<svg'));
    await oraclePage.setContent(`<!DOCTYPE html><html><body>${body}</body></html>`);
    oracleCache.set(key, await oraclePage.evaluate(`(${fillsIn})(document)`));
  }
  return oracleCache.get(key);
}

async function openPage(html) {
  const page = await browser.newPage();
  const requests = [];
  const errors = [];
  page.on('request', (r) => { if (r.url() !== pathToFileURL(html).href) requests.push(r.url()); });
  page.on('pageerror', (e) => errors.push(String(e)));
  page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
  // A script smuggled in by a hostile name would open one.
  page.on('dialog', async (d) => { errors.push('a dialog opened: ' + d.message()); await d.dismiss(); });
  const t0 = Date.now();
  await page.goto(pathToFileURL(html).href, { waitUntil: 'load' });
  await page.waitForFunction('window.btfsmView !== undefined');
  const loadMs = Date.now() - t0;
  return { page, requests, errors, loadMs };
}

const stepOf = (page) => page.evaluate('window.btfsmView.step()');

// The map's robots (a scenario's page): each circle's move from step 0 to
// the current step must be the trace's move of that run, at 100 px a metre
// with y up (within the half pixel the page's positions are rounded to and
// thinned by).
async function checkMap(page, what, k, runs) {
  const at = await page.evaluate(`[...document.querySelectorAll('#map circle.robot')].map((c) => [+c.getAttribute('cx'), +c.getAttribute('cy'), c.getAttribute('visibility')])`);
  if (at.length !== runs.length) { fail(`${what}: ${at.length} robots on the map, ${runs.length} runs`); return; }
  for (let i = 0; i < runs.length; i++) {
    const tr = runs[i].trace;
    if (!tr.length) continue;
    const s = tr[Math.min(k, tr.length - 1)];
    if (at[i][2] !== 'visible') { fail(`${what}: robot ${i} hidden at step ${k}`); continue; }
    if (!runs[i].origin) runs[i].origin = { px: null };
    if (k === 0) runs[i].origin.px = [at[i][0], at[i][1]];
    const o = runs[i].origin.px;
    if (!o) continue;
    const want = [100 * (s.x - tr[0].x), -100 * (s.y - tr[0].y)];
    const got = [at[i][0] - o[0], at[i][1] - o[1]];
    if (Math.abs(got[0] - want[0]) > 1.1 || Math.abs(got[1] - want[1]) > 1.1) {
      fail(`${what}: robot ${i} at step ${k} moved ${got.map((v) => v.toFixed(1))} px on the map, the trace ${want.map((v) => v.toFixed(1))}`);
    }
  }
}

// Compares every panel's fills at the page's current step with the oracle.
async function check(page, what, oracleArgv, lengths, runs) {
  const k = await stepOf(page);
  if (runs) await checkMap(page, what, k, runs);
  const n = lengths.length;
  let coloured = 0;
  const seen = [];
  for (let i = 0; i < n; i++) {
    const got = await page.evaluate(`(${fillsIn})(document.querySelector('#p${i} .diagram'))`);
    const want = await oracleFills(oracleArgv(i, Math.min(k, lengths[i] - 1)));
    const titles = Object.keys(want);
    if (titles.length === 0 || titles.length !== Object.keys(got).length) {
      fail(`${what}: step ${k}, panel ${i}: ${Object.keys(got).length} nodes on the page, ${titles.length} in the oracle`);
    }
    for (const t of titles) {
      if (got[t] !== want[t]) fail(`${what}: step ${k}, panel ${i}, node ${JSON.stringify(t)}: fill ${got[t]}, expected ${want[t]}`);
    }
    coloured += titles.filter((t) => /rgb\(255, 215, 0\)|rgb\(152, 251, 152\)|rgb\(255, 99, 71\)/.test(want[t])).length;
    seen.push(got);
  }
  return { k, coloured, fills: JSON.stringify(seen) };
}

// Drives a page through its controls; returns the fills seen per step.
async function drive(name, html, oracleArgv, lengths, shots, runs) {
  const { page, requests, errors } = await openPage(html);
  const total = await page.evaluate('window.btfsmView.total');
  const states = [];
  const at = async (what) => {
    const s = await check(page, `${name} (${what})`, oracleArgv, lengths, runs);
    states.push(s);
    return s;
  };
  await at('loaded');
  for (let j = 0; j < 3; j++) await page.keyboard.press('ArrowRight');
  if ((await stepOf(page)) !== Math.min(3, total - 1)) fail(`${name}: three ArrowRight presses did not reach step 3`);
  await at('arrow keys');
  await page.click('#next');
  await at('next button');
  // A click on the slider at 60% of its width.
  const box = await (await page.$('#slider')).boundingBox();
  await page.mouse.click(box.x + box.width * 0.6, box.y + box.height / 2);
  const mid = await stepOf(page);
  if (Math.abs(mid - 0.6 * (total - 1)) > 0.05 * total + 2) fail(`${name}: a click at 60% of the slider went to step ${mid} of ${total}`);
  await at('slider');
  if (shots) await page.screenshot({ path: join(opt.out, `${basename(html, '.html')}-slider.png`), fullPage: true });
  const gos = await page.$$('button.go');
  if (gos.length) {
    await gos[0].click();
    await at('divergence button');
    if (shots) await page.screenshot({ path: join(opt.out, `${basename(html, '.html')}-divergence.png`), fullPage: true });
  }
  await page.keyboard.press('End');
  if ((await stepOf(page)) !== total - 1) fail(`${name}: End did not reach the last step`);
  await at('End');
  await page.click('#prev');
  await at('prev button');
  await page.keyboard.press('Home');
  await at('Home');
  if (requests.length) fail(`${name}: the page requested ${requests.join(', ')}`);
  if (errors.length) fail(`${name}: the page reported ${errors.join('; ')}`);
  const distinct = new Set(states.map((s) => s.fills)).size;
  if (distinct < 2) fail(`${name}: no node changed fill over steps ${states.map((s) => s.k).join(', ')}`);
  if (!states.some((s) => s.coloured > 0)) fail(`${name}: no node coloured by a status at any step checked`);
  console.log(`${name}: ${lengths.length} panel(s), ${total} steps, steps ${states.map((s) => s.k).join(', ')} checked, ${distinct} distinct colourings`);
  await page.close();
}

for (const scenario of opt.scenarios) {
  const name = basename(scenario, '.toml');
  const html = resolve(join(opt.out, `${name}.html`));
  const trace = join(opt.out, `${name}.trace.json`);
  run(['view', scenario, '-o', html]);
  run(['sim', scenario, '--trace', trace, '--format', 'json'], [0, 1]);
  const runs = JSON.parse(readFileSync(trace, 'utf8')).policies;
  const lengths = runs.map((r) => r.trace.length);
  const oracle = (i, k) => ['dot', runs[i].file, '--trace', trace, '--step', String(k), '--policy', runs[i].policy];
  await drive(name, html, oracle, lengths, true, runs);
}

for (const log of opt.logs) {
  const name = basename(log, '.btlog');
  const html = resolve(join(opt.out, `log-${name}.html`));
  run(['view', log, '-o', html]);
  const report = JSON.parse(run(['log', 'report', log, '--format', 'json']));
  const records = report.records ?? report.status_changes ?? null;
  const page = await browser.newPage();
  await page.goto(pathToFileURL(html).href);
  const total = await page.evaluate('window.btfsmView.total');
  await page.close();
  if (records !== null && records !== total) fail(`${name}: ${total} steps on the page, ${records} records in the log`);
  // Step k of the page is the state after k + 1 records.
  const oracle = (_i, k) => ['log', 'dot', log, '--step', String(k + 1)];
  await drive(`log ${name}`, html, oracle, [total], true);
}

if (opt.scale) {
  const name = basename(opt.scale, '.toml');
  const html = resolve(join(opt.out, `${name}.html`));
  const trace = join(opt.out, `${name}.trace.json`);
  const t0 = Date.now();
  run(['view', opt.scale, '-o', html]);
  const writeMs = Date.now() - t0;
  run(['sim', opt.scale, '--trace', trace, '--format', 'json'], [0, 1]);
  const runs = JSON.parse(readFileSync(trace, 'utf8')).policies;
  const lengths = runs.map((r) => r.trace.length);
  const { page, loadMs, errors } = await openPage(html);
  const total = await page.evaluate('window.btfsmView.total');
  // In-page time of a jump from the first to the last step, style
  // recomputed (median of 5), and of a step back from the last.
  const jump = await page.evaluate(() => {
    const v = window.btfsmView, ms = [];
    for (let r = 0; r < 5; r++) {
      v.go(0);
      document.body.offsetHeight;
      const t = performance.now();
      v.go(v.total - 1);
      for (const s of document.querySelectorAll('.diagram ellipse, .diagram polygon')) getComputedStyle(s).fill;
      ms.push(performance.now() - t);
    }
    ms.sort((a, b) => a - b);
    const t = performance.now();
    v.go(v.total - 2);
    const back = performance.now() - t;
    return { median: ms[2], back };
  });
  await page.keyboard.press('End');
  const oracle = (i, k) => ['dot', runs[i].file, '--trace', trace, '--step', String(k), '--policy', runs[i].policy];
  await check(page, `${name} (End)`, oracle, lengths);
  if (errors.length) fail(`${name}: the page reported ${errors.join('; ')}`);
  const size = statSync(html).size;
  console.log(`scale ${name}: ${total} steps x ${lengths.length} panels, page ${size} bytes, written in ${writeMs} ms, loaded in ${loadMs} ms, jump to the last step ${jump.median.toFixed(1)} ms (median of 5), one step back from it ${jump.back.toFixed(1)} ms`);
  if (jump.median > 1000) fail(`${name}: a jump to the last step took ${jump.median} ms`);
  await page.screenshot({ path: join(opt.out, `${name}-last.png`) });
  await page.close();
}

if (opt.shots && opt.scenarios.length) {
  mkdirSync(opt.shots, { recursive: true });
  const first = basename(opt.scenarios[0], '.toml');
  for (const kind of ['slider', 'divergence']) {
    const f = join(opt.out, `${first}-${kind}.png`);
    if (existsSync(f)) copyFileSync(f, join(opt.shots, `view-${first}-${kind}.png`));
  }
}
await browser.close();
if (failed) {
  console.error(`${failed} failure(s)`);
  process.exit(1);
}
console.log('view pages: all checks passed');
