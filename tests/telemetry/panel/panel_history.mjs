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
    return { kinds: rows.map(r => r.dataset.kind), names: rows.map(r => r.children[2].textContent),
             when: rows.map(r => r.children[0].textContent), live: document.querySelectorAll("#faults tr").length };
  })()`);
  if (v.kinds.includes("fault")) break;
  await sleep(200);
}
const i = v.kinds.indexOf("fault");
if (v.names[i] !== "drive_fault") fail(`history row ${JSON.stringify(v)}`);
if (!/\(\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ\)/.test(v.when[i])) fail(`no wall-clock time: ${v.when[i]}`);
if (v.live !== 0) fail("the panel's own fault list is not empty: it heard the fault (the test's premise)");
const shot = await send("Page.captureScreenshot", { format: "png", captureBeyondViewport: true }, page);
writeFileSync(pngPath, Buffer.from(shot.data, "base64"));
console.log(`history shown in the browser: ${v.kinds.length} lines (${v.kinds.join(" ")})`);
browser.close();
process.exit(0);
