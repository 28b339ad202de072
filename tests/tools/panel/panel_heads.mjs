// The knotting heads' view in a real browser: the row tied knot by knot and the magazines' levels.
// Reads the page's DOM only (what the weaver sees): the cycle in progress and the tied knots advance
// together (cycle j of the stripe shows j knots tied per head, the knot in progress outlined), every head
// of the loom has a row in the heads table with one magazine level per slot, and the levels go down as
// knots are tied — by as many knots as the page says were tied.
// Usage: node --experimental-websocket panel_heads.mjs <chromium> <panel base url> <loom id> <png> <timeout s>
import { startCheck } from "./cdp.mjs";

const browser = await startCheck(60);
const { base, loomId, pngPath, fail, open, evaluate, screenshot } = browser;

const page = await open(`${base}/loom/${loomId}`);
const read = () => evaluate(page, `(() => {
  const s = document.getElementById("heads");
  if (!s) return null;
  const rows = [...document.querySelectorAll("#heads-table tr[data-head]")];
  return { knotting: s.dataset.knotting === "true", cycle: Number(s.dataset.cycle), row: Number(s.dataset.row),
           knots: document.querySelectorAll("#head-row .k").length,
           tied: document.querySelectorAll("#head-row .k.tied").length,
           now: document.querySelectorAll("#head-row .k.now").length,
           heads: rows.length,
           stock: rows.map(r => [...r.querySelectorAll(".mag")].map(m => Number(m.dataset.stock))),
           rowKnots: document.getElementById("row-knots")?.textContent,
           // The axes table: name and unit of every axis (the knotters and selectors the machine adds too).
           units: Object.fromEntries([...document.querySelectorAll("#axes tr")].slice(1)
             .map(r => [r.children[0].textContent, r.children[5].textContent])),
           // The beat-force chart's x labels (no beat yet while the heads tie the first row).
           xLabels: [...document.querySelectorAll('#force-chart text[y="242"]')].map(t => t.textContent) };
})()`);
const waitFor = (what, ok, seconds) => browser.waitFor(read, what, ok, seconds, 150);
const sum = a => a.flat().reduce((x, y) => x + y, 0);

// 1. The heads tie: a cycle in progress, one knot outlined per head, the cycles done shown tied. Early
// enough in the row that three more cycles follow in it (a page first read late in a row — a slow start
// under load — waits for the next row, instead of comparing knots across two rows).
const cyclesLeft = v => v.knots / v.heads - v.cycle;
const a = await waitFor("the heads tying, a few knots in, three more cycles to go in the row",
  v => v.knotting && v.cycle >= 2 && v.heads > 0 && cyclesLeft(v) > 3, 60);
if (a.now !== a.heads) fail(`${a.now} knots outlined as in progress, the loom has ${a.heads} heads`);
if (a.tied !== a.heads * a.cycle) fail(`${a.tied} knots shown tied at cycle ${a.cycle + 1}, want ${a.heads * a.cycle}`);
if (a.stock.some(h => h.length === 0 || h.some(n => !(n >= 0)))) fail(`magazine levels missing: ${JSON.stringify(a.stock)}`);
// Every axis names its unit, the ones the machine adds too (issue 22: they said "SI"): the knotting and
// selector servos are rotary (rad), the carriage linear (m).
const added = Object.keys(a.units).filter(n => /^(knotter|selector)_/.test(n));
if (added.length !== 2 * a.heads) fail(`${added.length} knotter/selector axes in the axes table, want ${2 * a.heads}: ${JSON.stringify(a.units)}`);
for (const [n, u] of Object.entries(a.units)) {
  const want = n === "carriage" ? "m" : "rad";
  if (u !== want) fail(`axis ${n} shows unit "${u}", want "${want}": ${JSON.stringify(a.units)}`);
}
if (a.xLabels.length !== 5 || new Set(a.xLabels).size !== 5) fail(`beat chart x labels ${JSON.stringify(a.xLabels)}: want five distinct`);
await screenshot(page);
// 2. Later in the same row: more knots tied, the yarn gone from the magazines knot for knot. The levels
// and the knots tied may reach the page a telemetry message apart (a loaded host showed the levels one
// cycle behind): the page is read until they agree, and the check below still fails a level that never
// catches up (timeout) or one that drops by more than the knots tied.
const used = v => sum(a.stock) - sum(v.stock);
const b = await waitFor("more knots tied in the same row, the levels caught up with them",
  v => v.knotting && v.row === a.row && v.cycle >= a.cycle + 3 && used(v) >= v.tied - a.tied, 60);
if (b.tied !== b.heads * b.cycle) fail(`${b.tied} knots shown tied at cycle ${b.cycle + 1}, want ${b.heads * b.cycle}`);
const tiedMore = b.tied - a.tied;
// Each cycle takes one knot of yarn per head at TAKE; the one in progress may or may not have taken it yet.
if (used(b) < tiedMore || used(b) > tiedMore + b.heads) {
  fail(`the magazines lost ${used(b)} knots of yarn while ${tiedMore} more knots were tied (${JSON.stringify(a.stock)} -> ${JSON.stringify(b.stock)})`);
}
console.log(`PASS: units of ${Object.keys(a.units).length} axes (${added.length} added) shown; ${b.heads} heads, cycle ${a.cycle + 1} -> ${b.cycle + 1} of the row: ${a.tied} -> ${b.tied} knots shown tied, ` +
  `magazines ${sum(a.stock)} -> ${sum(b.stock)} knots of yarn ("${b.rowKnots}"); screenshot ${pngPath}`);
browser.close();
process.exit(0);
