// The carpet view in a real browser (issue 29): the job queue, the carpet so far read back from the
// canvas's pixels (never the DOM's word for it), rows and ETA, and the yarn left per head x slot.
//   1. before the start: the queue lists both jobs (1 queued, 2 queued), the carpet is all grey, ETA "—";
//   2. after `ctl start` and a row or two: every knot of a woven row has its design colour (the palette of
//      the CSV, parsed here), every knot of a row not begun is grey (r = g = b); the ETA is rows left x the
//      mean whole row shown;
//   3. paused (no row end can come), the yarn levels shown are magazines.txt's, and the low ones marked;
//   4. resumed to the carpet's last row: every row before it in the design's colours; then job 1
//      carpet_done and job 2 (queued) shown next.
// Usage: node --experimental-websocket panel_carpet.mjs <chromium> <panel base> <loom id> <png> <timeout s>
//          <loomctl> <socket> <design csv> <state dir> <rows>
import { execFileSync } from "node:child_process";
import { readFileSync } from "node:fs";
import { startCheck } from "./cdp.mjs";

const browser = await startCheck(150);
const { base, loomId, pngPath, rest, fail, open, evaluate, screenshot } = browser;
const [loomctl, sock, designCsv, stateDir, rowsArg] = rest;
const rows = Number(rowsArg);
const ctl = (...a) => execFileSync(loomctl, ["ctl", "--socket", sock, ...a], { encoding: "utf8" });

// The design, from its file: palette codes to colours, grid rows bottom-up (row 1 = the file's last line).
const palette = {};
const grid = [];
for (const line of readFileSync(designCsv, "utf8").split("\n")) {
  const t = line.trim();
  if (!t || t.startsWith("#")) continue;
  const cells = t.split(",").map(c => c.trim());
  if (cells[0] === "palette") { palette[cells[1]] = [1, 3, 5].map(o => parseInt(cells[2].substr(o, 2), 16)); continue; }
  grid.push(cells);
}
grid.reverse();
const width = grid[0].length;
const designColour = (r, k) => palette[grid[r % grid.length][k]];

const page = await open(`${base}/loom/${loomId}`);
const read = () => evaluate(page, `(() => {
  const s = document.getElementById("carpet");
  const c = document.getElementById("carpet-canvas");
  if (!s || !c) return null;
  let px = null;
  if (c.width > 1) px = Array.from(c.getContext("2d").getImageData(0, 0, c.width, c.height).data);
  return { job: Number(s.dataset.job), state: s.dataset.state, done: Number(s.dataset.rowsDone), rows: Number(s.dataset.rows),
    rowsText: document.getElementById("carpet-rows").textContent, eta: document.getElementById("carpet-eta").textContent,
    etaS: document.getElementById("carpet-eta").dataset.etaS, rowTime: document.getElementById("carpet-row-time").textContent,
    queue: [...document.querySelectorAll("#job-queue tr[data-job]")].map(r => [Number(r.dataset.job), r.children[1].textContent, r.dataset.state]),
    yarn: [...document.querySelectorAll("#job-yarn tr[data-head]")].map(r => [...r.querySelectorAll("td[data-slot]")].map(t => [Number(t.dataset.stock), t.classList.contains("low")])),
    w: c.width, h: c.height, px };
})()`);
const waitFor = (what, ok, seconds) => browser.waitFor(read, what, ok, seconds, 200);

// The canvas against the design: rows below `done` in the design's colours, rows above `done` grey.
function checkPixels(v, label) {
  if (v.w !== width || v.h !== rows) fail(`${label}: canvas ${v.w}x${v.h}, want ${width}x${rows}`);
  let woven = 0, grey = 0;
  for (let r = 0; r < rows; ++r) {
    if (r === v.done && v.done < rows) continue;  // the row being knotted: part tied, part not
    const y = rows - 1 - r;  // row 1 at the bottom
    for (let k = 0; k < width; ++k) {
      const o = 4 * (y * width + k), got = v.px.slice(o, o + 3), want = designColour(r, k);
      if (r < v.done) {
        if (got.join() !== want.join()) fail(`${label}: woven row ${r + 1} knot ${k + 1} is rgb(${got}), the design says rgb(${want})`);
        ++woven;
      } else {
        if (got[0] !== got[1] || got[1] !== got[2]) fail(`${label}: row ${r + 1} (not woven) knot ${k + 1} is rgb(${got}), not grey`);
        if (got.join() === want.join()) fail(`${label}: row ${r + 1} (not woven) knot ${k + 1} shows its colour`);
        ++grey;
      }
    }
  }
  return { woven, grey };
}

// 1. Queued, before the start.
const a = await waitFor("job 1 queued with its knot map drawn", v => v.job === 1 && v.state === "queued" && v.px, 60);
const want = JSON.stringify([[1, "queued"], [2, "queued"]]);
if (JSON.stringify(a.queue.map(q => [q[0], q[2]])) !== want) fail(`queue ${JSON.stringify(a.queue)}, want jobs ${want}`);
if (a.eta !== "—" || a.rowsText !== `0 / ${rows}`) fail(`before the start: rows "${a.rowsText}", ETA "${a.eta}"; want "0 / ${rows}" and "—"`);
const pa = checkPixels(a, "queued");
if (pa.grey !== (rows - 1) * width) fail(`queued: ${pa.grey} grey knots, want ${(rows - 1) * width}`);

// 2. Started: rows woven in the design's colours, the ETA from the mean whole row.
ctl("start");
const b = await waitFor("a row woven, the ETA known", v => v.state === "current" && v.done >= 1 && v.done < rows - 1 && v.etaS !== "", 90);
const pb = checkPixels(b, `after ${b.done} row(s)`);
const mean = parseFloat(b.rowTime);
const etaB = Number(b.etaS);
if (!(mean > 0) || Math.abs(etaB - (rows - b.done) * mean) > 0.05 * (rows - b.done) + 1e-9) {
  fail(`ETA ${etaB} s with ${rows - b.done} rows left and a mean row of "${b.rowTime}"`);
}
if (b.rowsText !== `${b.done} / ${rows}`) fail(`rows shown "${b.rowsText}", the section says ${b.done}`);
await screenshot(page);

// 3. Paused: no row end until resumed, so the levels shown are the ones on disk.
ctl("pause");
await new Promise(r => setTimeout(r, 1500));
const mags = () => readFileSync(`${stateDir}/magazines.txt`, "utf8").split("\n").filter(l => l.startsWith("head."))
  .map(l => l.split("=")[1].trim().split(/\s+/).map(Number));
const full = Number(/knots_per_slot = (\d+)/.exec(readFileSync(`${stateDir}/magazines.txt`, "utf8"))[1]);
const c = await waitFor("the yarn shown equal to magazines.txt", v => JSON.stringify(v.yarn.map(h => h.map(x => x[0]))) === JSON.stringify(mags()), 30);
for (const h of c.yarn) for (const [n, low] of h) if (low !== (n < 0.1 * full)) fail(`level ${n} of ${full} marked ${low ? "" : "not "}low`);
if (c.done < b.done) fail(`rows went back: ${b.done} -> ${c.done}`);
ctl("resume");

// 4. The carpet's last row: every row before it in its colours; then job 1 carpet_done, job 2 shown next.
const e = await waitFor("job 1's last row", v => v.job === 1 && v.done === rows - 1, 120);
const pe = checkPixels(e, "at the last row");
if (pe.woven !== (rows - 1) * width) fail(`at the last row: ${pe.woven} knots in colour, want ${(rows - 1) * width}`);
const d = await waitFor("the carpet done", v => v.queue.length === 2 && v.queue[0][2] === "carpet_done", 120);
if (d.job !== 2 || d.state !== "queued") fail(`after job 1: the section shows job ${d.job} (${d.state}), want job 2 queued`);
const q1 = d.queue[0];
const etaTexts = [a.eta, b.eta];
console.log(`PASS: queue ${JSON.stringify(a.queue)} -> ${JSON.stringify(d.queue)}; after ${b.done} row(s) ${pb.woven} knots ` +
  `in the design's colours and ${pb.grey} grey; ETA ${JSON.stringify(etaTexts)} (${etaB} s = ${rows - b.done} rows x ${mean} s); ` +
  `yarn ${JSON.stringify(c.yarn.map(h => h.map(x => x[0])))} = magazines.txt; job ${q1[0]} ${q1[2]}; screenshot ${pngPath}`);
browser.close();
process.exit(0);
