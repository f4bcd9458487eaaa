// The diff diagram of `btfsm compare --format markdown` against Mermaid's
// own parser (mermaid 11, in jsdom): for every pair A B given, the
// ```mermaid block of the markdown report must parse, and the parsed
// flowchart must hold what the named edit script (`compare --mode named
// --format json`) and `analyze` of B say:
//   vertices = V(B) + vertices removed + 3 legend nodes,
//   edges    = E(B) + arcs removed,
//   nodes of class `added`   = vertices added + 1 (legend),
//   nodes of class `removed` = vertices removed + 1,
//   nodes of class `changed` = distinct vertices relabelled or reordered + 1,
//   and every node id is generated (v<i>, g<i>, x<i>, l<i>), never a name.
// Usage: node check_diff.mjs BTFSM A1 B1 [A2 B2 ...]   (exit 1 on any miss)
import { JSDOM } from 'jsdom';
import { execFileSync } from 'node:child_process';

const dom = new JSDOM('<!doctype html><html><body></body></html>');
globalThis.window = dom.window;
globalThis.document = dom.window.document;
const { default: mermaid } = await import('mermaid');

const [btfsm, ...files] = process.argv.slice(2);
if (files.length % 2 !== 0) {
  console.error('check_diff.mjs: give pairs of files');
  process.exit(2);
}
const run = (args) => execFileSync(btfsm, args, { encoding: 'utf8', stdio: ['ignore', 'pipe', 'ignore'] });
let failed = 0;
const expect = (pair, what, got, want) => {
  if (got !== want) {
    console.error(`${pair}: ${what}: mermaid has ${got}, btfsm says ${want}`);
    failed++;
  }
};
for (let i = 0; i < files.length; i += 2) {
  const [a, b] = [files[i], files[i + 1]];
  const pair = `${a} -> ${b}`;
  const md = run(['compare', a, b, '--mode', 'named', '--format', 'markdown']);
  const m = md.match(/^(`{3,})mermaid\n([\s\S]*?)^\1$/m);
  if (!m) {
    console.error(`${pair}: no mermaid block in the markdown report`);
    failed++;
    continue;
  }
  const text = m[2];
  const s = JSON.parse(run(['compare', a, b, '--mode', 'named', '--format', 'json'])).named.edit_script;
  const g = JSON.parse(run(['analyze', b, '--format', 'json'])).policies[0];
  try {
    await mermaid.parse(text);
  } catch (e) {
    console.error(`${pair}: mermaid cannot parse the diff: ${String(e.message || e).split('\n').slice(0, 3).join(' | ')}`);
    failed++;
    continue;
  }
  const db = (await mermaid.mermaidAPI.getDiagramFromText(text)).db;
  const v = [...db.getVertices().values()];
  const removedArcs = s.arcs_removed.reduce((n, x) => n + x.count, 0);
  const changed = new Set([...s.relabelled, ...s.reordered].map((x) => x.key).filter((k) => k !== ''));
  const withClass = (c) => v.filter((x) => (x.classes || []).includes(c)).length;
  expect(pair, 'vertices', v.length, g.vertices + s.vertices_removed.length + 3);
  expect(pair, 'edges', db.getEdges().length, g.edges + removedArcs);
  expect(pair, 'added nodes', withClass('added'), s.vertices_added.length + 1);
  expect(pair, 'removed nodes', withClass('removed'), s.vertices_removed.length + 1);
  expect(pair, 'changed nodes', withClass('changed'), changed.size + 1);
  expect(pair, 'generated ids', v.filter((x) => /^[vgxl]\d+$/.test(x.id)).length, v.length);
}
console.log(`mermaid diff oracle: ${files.length / 2 - failed} of ${files.length / 2} pairs parse with their edit script`);
process.exit(failed ? 1 : 0);
