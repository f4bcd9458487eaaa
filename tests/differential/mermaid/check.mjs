// The Mermaid export (`btfsm convert --to mermaid`) against Mermaid's own
// parser (mermaid 11, in jsdom): every policy given must parse, and the
// parsed diagram must hold the policy's graph as `btfsm analyze` counts it.
//   BT (flowchart):  vertices = V, edges = E, one vertex per node id n<i>.
//   FSM/HFSM (stateDiagram-v2): states s<i> = V - top-level outcomes,
//   composite states = containers (parallel states included),
//   arrows from a start pseudo-state = containers + 1 (the initial state of
//   every region), where each of the D regions of the P parallel states
//   (Mermaid's `--` dividers) has its own start instead of the parallel
//   state's: containers + 1 - P + D, transitions (arrows between states) =
//   E - (containers - P + D) (btfsm's graph has one initial arc per region).
// Usage: node check.mjs BTFSM [FLAG...] -- FILE...   (FLAGs go to both
// commands, e.g. --nodes-model; exit 1 when any policy disagrees)
import { JSDOM } from 'jsdom';
import { execFileSync } from 'node:child_process';

const dom = new JSDOM('<!doctype html><html><body></body></html>');
globalThis.window = dom.window;
globalThis.document = dom.window.document;
const { default: mermaid } = await import('mermaid');

const [btfsm, ...rest] = process.argv.slice(2);
const cut = rest.indexOf('--');
const flags = cut < 0 ? [] : rest.slice(0, cut);
const files = cut < 0 ? rest : rest.slice(cut + 1);
let failed = 0;
const expect = (file, what, got, want) => {
  if (got !== want) {
    console.error(`${file}: ${what}: mermaid has ${got}, btfsm analyze says ${want}`);
    failed++;
  }
};
for (const file of files) {
  const text = execFileSync(btfsm, ['convert', file, '--to', 'mermaid', ...flags], { encoding: 'utf8', stdio: ['ignore', 'pipe', 'ignore'] });
  const a = JSON.parse(execFileSync(btfsm, ['analyze', file, '--format', 'json', ...flags], { encoding: 'utf8', stdio: ['ignore', 'pipe', 'ignore'] })).policies[0];
  try {
    await mermaid.parse(text);
  } catch (e) {
    console.error(`${file}: mermaid cannot parse the export: ${String(e.message || e).split('\n').slice(0, 3).join(' | ')}`);
    failed++;
    continue;
  }
  const db = (await mermaid.mermaidAPI.getDiagramFromText(text)).db;
  if (a.kind === 'bt') {
    const v = [...db.getVertices().values()];
    expect(file, 'vertices', v.length, a.vertices);
    expect(file, 'edges', db.getEdges().length, a.edges);
    expect(file, 'generated ids', v.filter((x) => /^n\d+$/.test(x.id)).length, a.vertices);
  } else {
    const g = db.getData();
    const parallels = a.counts.parallel_state ?? 0;
    const containers = (a.counts.container ?? 0) + parallels;
    const dividers = g.nodes.filter((n) => n.shape === 'divider').length;
    const outcomes = a.counts.outcome ?? 0;
    const states = g.nodes.filter((n) => /^s\d+$/.test(n.id));
    expect(file, 'states', states.length, a.vertices - outcomes);
    expect(file, 'composite states', g.nodes.filter((n) => n.isGroup && n.shape !== 'divider').length, containers);
    if (parallels === 0) expect(file, 'regions of parallel states', dividers, 0);
    const starts = new Set(g.nodes.filter((n) => n.shape === 'stateStart').map((n) => n.id));
    const ends = new Set(g.nodes.filter((n) => n.shape === 'stateEnd').map((n) => n.id));
    // A region that starts in one of its outcomes (an SCXML state holding
    // only a `<final>`) has a start arrow to it but no arc in btfsm's graph
    // (the machine's own start, `root_start`, is no arc either way).
    const toOutcome = g.edges.filter((e) => starts.has(e.start) && e.start !== 'root_start' && /^o\d+(_\d+)?$/.test(e.end)).length;
    const regions = containers - parallels + dividers;
    expect(file, 'transitions', g.edges.filter((e) => !starts.has(e.start) && !ends.has(e.end)).length, a.edges - (regions - toOutcome));
    expect(file, 'initial arrows', g.edges.filter((e) => starts.has(e.start)).length, regions + 1);
  }
}
console.log(`mermaid oracle: ${files.length - failed} of ${files.length} policies parse with their graph`);
process.exit(failed ? 1 : 0);
