// The loom's page in a real browser shows the persisted fault history (faults.log through the panel),
// with wall-clock times, for a fault the panel itself never heard.
// Usage: node --experimental-websocket panel_history.mjs <chromium> <panel base url> <loom id> <png> <timeout s>
import { startCheck } from "./cdp.mjs";

const browser = await startCheck(30);
const { base, loomId, pngPath, fail, open, evaluate, screenshot } = browser;
const page = await open(`${base}/loom/${loomId}`);
const historyRead = () => evaluate(page, `(() => {
  const rows = [...document.querySelectorAll("#history tr[data-kind]")];
  return { download: document.getElementById("faults-log")?.getAttribute("href") || null, kinds: rows.map(r => r.dataset.kind), names: rows.map(r => r.children[2].textContent),
           when: rows.map(r => r.children[0].textContent), live: document.querySelectorAll("#faults tr").length };
})()`);
const v = await browser.waitFor(historyRead, "the fault in the page's history table", h => h.kinds.includes("fault"), 20);
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
const waitScope = (what, ok) => browser.waitFor(scopeRead, what, ok, 20);
const first = await waitScope("the first axis plotted", s => s.points >= 10 && s.strips === 3);
await evaluate(page, `(() => { const s = document.getElementById("scope-axis"); s.value = "carriage";
  s.dispatchEvent(new Event("change", { bubbles: true })); })()`);
const carriage = await waitScope("the carriage plotted", s => s.axis === "carriage" && s.points >= 10 && s.strips === 3);
if (/\d[eE][+-]\d/.test(carriage.text)) fail(`scientific notation on the page: ${carriage.text}`);
if (!carriage.text.includes("velocity m/s") || !carriage.units.includes("m") || !carriage.units.includes("rad")) {
  fail(`units missing: ${JSON.stringify(carriage)}`);
}
console.log(`scope: ${first.axis} then carriage plotted (${carriage.points} samples each of position, velocity, following error)`);
await screenshot(page);
console.log(`history shown in the browser: ${v.kinds.length} lines (${v.kinds.join(" ")})`);
browser.close();
process.exit(0);
