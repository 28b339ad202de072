// The loom's page in a real browser shows the persisted fault history (faults.log through the panel),
// with wall-clock times, for a fault the panel itself never heard.
// Usage: node --experimental-websocket panel_history.mjs <chromium> <panel base url> <loom id> <png> <timeout s>
import { writeFileSync } from "node:fs";
import { launch, sleep } from "./cdp.mjs";

const [chromiumBin, base, loomId, pngPath, timeoutArg] = process.argv.slice(2);
const timeoutMs = Number(timeoutArg || 30) * 1000;
let browser = null;
const fail = msg => { console.error("FAIL: " + msg); browser?.close(); process.exit(1); };
setTimeout(() => fail(`gave up after ${timeoutMs / 1000} s`), timeoutMs).unref();
browser = await launch(chromiumBin, fail);
const { send, open, evaluate } = browser;
const page = await open(`${base}/loom/${loomId}`);
let v = null;
for (;;) {
  v = await evaluate(page, `(() => {
    const rows = [...document.querySelectorAll("#history tr[data-kind]")];
    return { download: document.getElementById("faults-log")?.getAttribute("href") || null, kinds: rows.map(r => r.dataset.kind), names: rows.map(r => r.children[2].textContent),
             when: rows.map(r => r.children[0].textContent), live: document.querySelectorAll("#faults tr").length };
  })()`);
  if (v.kinds.includes("fault")) break;
  await sleep(200);
}
const i = v.kinds.indexOf("fault");
if (v.names[i] !== "drive_fault") fail(`history row ${JSON.stringify(v)}`);
if (!/\(\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ\)/.test(v.when[i])) fail(`no wall-clock time: ${v.when[i]}`);
if (v.download !== `/api/loom/${loomId}/faults.log`) fail(`no faults.log download link: ${v.download}`);
if (v.live !== 0) fail("the panel's own fault list is not empty: it heard the fault (the test's premise)");
// The scope strip: the first axis plotted, then the carriage picked from the list and plotted; the axes
// table and the strips carry units and no scientific notation.
const scopeRead = () => evaluate(page, `(() => {
  const sc = document.getElementById("scope"), p = document.getElementById("scope-position");
  const v = document.getElementById("scope-velocity"), e = document.getElementById("scope-following-error");
  return { axis: sc ? sc.dataset.axis : null, points: p ? Number(p.dataset.points) : 0,
           strips: [p, v, e].filter(x => x).length, text: (sc ? sc.textContent : "") + " " +
           (document.getElementById("axes")?.textContent || ""), units: [...document.querySelectorAll("#axes tr td:nth-child(6)")].map(td => td.textContent) };
})()`);
const waitScope = async (what, ok) => {
  for (let i = 0; i < 100; ++i) { const s = await scopeRead(); if (ok(s)) return s; await sleep(200); }
  fail(`${what}: ${JSON.stringify(await scopeRead())}`);
};
const first = await waitScope("the first axis plotted", s => s.points >= 10 && s.strips === 3);
await evaluate(page, `(() => { const s = document.getElementById("scope-axis"); s.value = "carriage";
  s.dispatchEvent(new Event("change", { bubbles: true })); })()`);
const carriage = await waitScope("the carriage plotted", s => s.axis === "carriage" && s.points >= 10 && s.strips === 3);
if (/\d[eE][+-]\d/.test(carriage.text)) fail(`scientific notation on the page: ${carriage.text}`);
if (!carriage.text.includes("velocity m/s") || !carriage.units.includes("m") || !carriage.units.includes("rad")) {
  fail(`units missing: ${JSON.stringify(carriage)}`);
}
console.log(`scope: ${first.axis} then carriage plotted (${carriage.points} samples each of position, velocity, following error)`);
const shot = await send("Page.captureScreenshot", { format: "png", captureBeyondViewport: true }, page);
writeFileSync(pngPath, Buffer.from(shot.data, "base64"));
console.log(`history shown in the browser: ${v.kinds.length} lines (${v.kinds.join(" ")})`);
browser.close();
process.exit(0);
