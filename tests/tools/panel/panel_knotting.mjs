// Knotting mode in a real browser: the loom parks before each row for the weaver; the panel shows the
// design row to knot next (its colour codes, left to right) and its place in the design; the loom
// waits; the weaver presses "Row knotted" on the panel, which goes through the board's control socket;
// the loom weaves that row and parks again with the panel showing the next design row.
// Usage: node --experimental-websocket panel_knotting.mjs <chromium> <panel base url> <loom id> <png>
//        <timeout s> <design rows JSON: [[codes of design row 1], [codes of design row 2]]> <height>
//        <pairing code from `loomctl ctl pair`: "Row knotted" is offered only to a paired device>
import { sleep, startCheck } from "./cdp.mjs";

const browser = await startCheck(60);
const { base, loomId, pngPath, rest, fail, open, evaluate, screenshot } = browser;
const [rowsJson, heightArg, pairCode] = rest;
const expected = JSON.parse(rowsJson);
const height = Number(heightArg);

const page = await open(`${base}/loom/${loomId}`);
const read = () => evaluate(page, `(() => {
  const d = document.getElementById("design"), st = document.querySelector(".state");
  return { state: st ? st.dataset.state : null,
           rowsDone: Number(document.getElementById("rows-done")?.textContent),
           nextRow: d ? Number(d.dataset.nextRow) : null, height: d ? Number(d.dataset.height) : null,
           knots: [...document.querySelectorAll("#next-row .knot")].map(k => k.dataset.code),
           button: !!document.querySelector('button[data-cmd="next"]:not([disabled])') };
})()`);
const waitFor = (what, ok, seconds) => browser.waitFor(read, what, ok, seconds);
const same = (a, b) => JSON.stringify(a) === JSON.stringify(b);

// 0. Unpaired, the page offers no "Row knotted" (a starting command); the weaver pairs the device.
const unpaired = await waitFor("the pairing field of an unpaired device",
  v => v.state === "await_knotting", 40);
if (unpaired.button) fail("an unpaired device was offered \"Row knotted\"");
await evaluate(page, `(() => { document.getElementById("pair-code").value = "${pairCode}";
  document.querySelector('button[data-pair]').click(); })()`);
// 1. Parked before row 1, showing design row 1 (the bottom line of the picture) with its codes.
const first = await waitFor("the loom waiting for the weaver with design row 1 shown",
  v => v.state === "await_knotting" && v.nextRow === 1 && v.knots.length > 0 && v.button, 40);
if (first.height !== height) fail(`design height ${first.height}, want ${height}`);
if (!same(first.knots, expected[0])) fail(`design row 1 shown as ${JSON.stringify(first.knots)}, want ${JSON.stringify(expected[0])}`);
// 2. It waits for the weaver: nothing is woven while the row is being knotted.
await sleep(1500);
const still = await read();
if (still.state !== "await_knotting" || still.rowsDone !== 0) fail(`did not wait for the weaver: ${JSON.stringify(still)}`);
await screenshot(page);
// 3. The weaver presses the panel's button (a DOM click: the page's own fetch to the control socket).
await evaluate(page, `document.querySelector('button[data-cmd="next"]').click()`);
// 4. Row 1 is woven, and the loom parks again with design row 2 shown.
const second = await waitFor("row 1 woven and design row 2 shown",
  v => v.rowsDone === 1 && v.state === "await_knotting" && v.nextRow === 2 && v.knots.length > 0, 40);
if (!same(second.knots, expected[1])) fail(`design row 2 shown as ${JSON.stringify(second.knots)}, want ${JSON.stringify(expected[1])}`);
const reply = await evaluate(page, `document.getElementById("ctl-reply")?.textContent`);
console.log(`PASS: waited at design row 1/${height} (${first.knots.join(",")}), "${reply}" from the panel's button, ` +
  `wove row 1, now waits at design row 2 (${second.knots.join(",")}); screenshot ${pngPath}`);
browser.close();
process.exit(0);
