// Drives headless Chromium through the DevTools protocol (node's own WebSocket, no npm packages) to
// load loom-panel's pages during a simulated run, and checks what a person would see in the DOM:
// the loom's row count advancing and every beat force of the current row drawn in the target band;
// the hall page listing the loom. Writes a screenshot of the loom page.
// Usage: node --experimental-websocket panel_browser.mjs <chromium> <panel base url> <loom id> <png> <timeout s>
import { spawn } from "node:child_process";
import { mkdtempSync, writeFileSync, rmSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";

const [chromiumBin, base, loomId, pngPath, timeoutArg] = process.argv.slice(2);
const minBeats = Number(process.env.PANEL_MIN_BEATS || 3);  // more for a fuller screenshot
const timeoutMs = Number(timeoutArg || 60) * 1000;
const started = Date.now();
const fail = msg => { console.error("FAIL: " + msg); cleanup(); process.exit(1); };
const profile = mkdtempSync(join(tmpdir(), "loom_panel_chromium."));
const chrome = spawn(chromiumBin, [
  "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
  "--disable-background-networking", "--disable-component-update", "--disable-sync",
  "--disable-dev-shm-usage", `--user-data-dir=${profile}`, "--remote-debugging-port=0",
  "--remote-debugging-address=127.0.0.1", "--window-size=1200,1500", "about:blank"], { stdio: ["ignore", "ignore", "pipe"] });
function cleanup() { try { chrome.kill("SIGKILL"); } catch {} try { rmSync(profile, { recursive: true, force: true }); } catch {} }
setTimeout(() => fail(`gave up after ${timeoutMs / 1000} s`), timeoutMs).unref();

const wsUrl = await new Promise((resolve, reject) => {
  let err = "";
  chrome.stderr.on("data", d => {
    err += d;
    const m = err.match(/DevTools listening on (ws:\/\/\S+)/);
    if (m) resolve(m[1]);
  });
  chrome.on("exit", code => reject(new Error(`chromium exited ${code}: ${err.slice(-2000)}`)));
}).catch(e => fail(e.message));

const ws = new WebSocket(wsUrl);
await new Promise((res, rej) => { ws.onopen = res; ws.onerror = () => rej(new Error("devtools websocket")); });
let nextId = 1;
const pending = new Map();
ws.onmessage = ev => {
  const msg = JSON.parse(ev.data);
  if (msg.id && pending.has(msg.id)) {
    const { resolve, reject } = pending.get(msg.id);
    pending.delete(msg.id);
    msg.error ? reject(new Error(JSON.stringify(msg.error))) : resolve(msg.result);
  }
};
const send = (method, params = {}, sessionId) => new Promise((resolve, reject) => {
  const id = nextId++;
  pending.set(id, { resolve, reject });
  ws.send(JSON.stringify(sessionId ? { id, method, params, sessionId } : { id, method, params }));
});
const sleep = ms => new Promise(r => setTimeout(r, ms));

async function open(url) {
  const { targetId } = await send("Target.createTarget", { url });
  const { sessionId } = await send("Target.attachToTarget", { targetId, flatten: true });
  await send("Runtime.enable", {}, sessionId);
  return sessionId;
}
async function evaluate(session, expression) {
  const r = await send("Runtime.evaluate", { expression, returnByValue: true }, session);
  return r.result.value;
}

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
const shot = await send("Page.captureScreenshot", { format: "png", captureBeyondViewport: true }, loomPage);
writeFileSync(pngPath, Buffer.from(shot.data, "base64"));

// ---- the hall page lists the loom ----
const hallPage = await open(`${base}/`);
let hall = null;
for (let i = 0; i < 40; i++) {
  hall = await evaluate(hallPage, `[...document.querySelectorAll("#hall tr[data-loom]")].map(tr => tr.dataset.loom)`);
  if (hall && hall.includes(loomId)) break;
  await sleep(250);
}
if (!hall || !hall.includes(loomId)) fail(`the hall page does not list ${loomId}: ${JSON.stringify(hall)}`);
const hallShot = await send("Page.captureScreenshot", { format: "png" }, hallPage);
writeFileSync(pngPath.replace(/\.png$/, "_hall.png"), Buffer.from(hallShot.data, "base64"));

console.log(`PASS: panel showed row ${first.row} -> ${last.row}, ${last.forces.length} beat forces in band ` +
  `(${last.forces.map(f => f.n).join(" ")}), hall lists ${hall.join(",")}; screenshot ${pngPath}`);
ws.close();
cleanup();
process.exit(0);
