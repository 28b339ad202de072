// Drives headless Chromium through the DevTools protocol (node's own WebSocket, no npm packages) to
// load loom-panel's pages during a simulated run, and checks what a person would see in the DOM:
// the loom's row count advancing and every beat force of the current row drawn in the target band;
// the hall page listing the loom. Writes a screenshot of the loom page.
// Usage: node --experimental-websocket panel_browser.mjs <chromium> <panel base url> <loom id> <png> <timeout s>
import { sleep, startCheck } from "./cdp.mjs";

const browser = await startCheck(60);
const { base, loomId, pngPath, started, timeoutMs, fail, open, evaluate, screenshot } = browser;
const minBeats = Number(process.env.PANEL_MIN_BEATS || 3);  // more for a fuller screenshot

// ---- the loom page ----
const loomPage = await open(`${base}/loom/${loomId}`);
const read = () => evaluate(loomPage, `(() => {
  const row = document.getElementById("row");
  const state = document.querySelector(".state");
  return { row: row ? Number(row.dataset.row) : null, state: state ? state.dataset.state : null,
           beatsRow: document.getElementById("beats") ? Number(document.getElementById("beats").dataset.row) : null,
           forces: [...document.querySelectorAll("#beats td.force")].map(td => ({ n: td.textContent, cls: td.className })),
           chart: !!document.getElementById("force-chart"), conn: document.getElementById("conn")?.textContent };
})()`);
let first = null, last = null;
while (Date.now() - started < timeoutMs - 5000) {
  last = await read();
  if (last && last.row !== null && !Number.isNaN(last.row)) {
    if (first === null) first = last;
    // The row advanced and the beats shown are the new row's (the previous row is drawn beside them).
    if (last.row >= first.row + 1 && last.beatsRow === last.row && last.forces.length >= minBeats) break;
  }
  await sleep(250);
}
if (first === null) fail(`the loom page never showed a row (last DOM read: ${JSON.stringify(last)})`);
if (!last || !(last.row >= first.row + 1)) fail(`the row count did not advance: first ${first.row}, last ${last.row}`);
if (!last.chart) fail("no beat-force chart on the page");
if (last.beatsRow !== last.row) fail(`the beats shown are row ${last.beatsRow}'s, not row ${last.row}'s`);
if (last.forces.length < 3) fail(`fewer than 3 beat forces shown: ${JSON.stringify(last.forces)}`);
for (const f of last.forces) {
  const n = Number(f.n);
  if (!(n >= 80 && n <= 100) || !f.cls.includes("in-band") || f.cls.includes("out-of-band")) {
    fail(`beat force ${f.n} N (class '${f.cls}') is not drawn in the 80-100 N band`);
  }
}
await screenshot(loomPage);

// ---- the hall page lists the loom ----
const hallPage = await open(`${base}/`);
let hall = null;
for (let i = 0; i < 40; i++) {
  hall = await evaluate(hallPage, `[...document.querySelectorAll("#hall tr[data-loom]")].map(tr => tr.dataset.loom)`);
  if (hall && hall.includes(loomId)) break;
  await sleep(250);
}
if (!hall || !hall.includes(loomId)) fail(`the hall page does not list ${loomId}: ${JSON.stringify(hall)}`);
await screenshot(hallPage, pngPath.replace(/\.png$/, "_hall.png"));

console.log(`PASS: panel showed row ${first.row} -> ${last.row}, ${last.forces.length} beat forces in band ` +
  `(${last.forces.map(f => f.n).join(" ")}), hall lists ${hall.join(",")}; screenshot ${pngPath}`);
browser.close();
process.exit(0);
