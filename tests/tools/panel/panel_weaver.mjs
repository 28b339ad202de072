// The weaver answers the knotting heads from the panel (issue 30): a paired page shows the heads' request
// (a knot to tie by hand) with a button that answers it; before, the page offered only Pause and Stop
// while the heads waited. Pairs the page, waits for the request, checks the button's words name what was
// asked, presses it, and sees the request gone and the heads tying on.
// Usage: node --experimental-websocket panel_weaver.mjs <chromium> <panel base url> <loom id> <png>
//        <timeout s> <pairing code from `loomctl ctl pair`>
import { startCheck } from "./cdp.mjs";

const browser = await startCheck(90);
const { base, loomId, pngPath, rest, fail, open, evaluate, screenshot } = browser;
const [pairCode] = rest;

const page = await open(`${base}/loom/${loomId}`);
const read = () => evaluate(page, `(() => {
  const st = document.querySelector(".state"), b = document.querySelector('button[data-cmd="next"]');
  const q = document.getElementById("weaver-request"), a = document.getElementById("weaver-answer");
  return { state: st ? st.dataset.state : null, paired: !document.getElementById("pair-code"),
           ask: q ? q.dataset.ask : null, asked: a ? a.textContent : null,
           button: b && !b.disabled ? { ask: b.dataset.ask, label: b.textContent } : null,
           reply: document.getElementById("ctl-reply")?.textContent || "" };
})()`);
const waitFor = (what, ok, seconds) => browser.waitFor(read, what, ok, seconds);

await waitFor("the operator section", v => v.state !== null, 40);
await evaluate(page, `(() => { document.getElementById("pair-code").value = "${pairCode}";
  document.querySelector('button[data-pair]').click(); })()`);
await waitFor("the page paired", v => v.paired, 20);
// The heads ask the weaver (a broken yarn: a knot to tie by hand).
const asked = await waitFor("the heads' request with its answer button",
  v => v.state === "knotting" && v.ask && v.button, 60);
if (asked.button.ask !== asked.ask) fail(`the button answers '${asked.button.ask}', the heads asked '${asked.ask}'`);
const words = { tie_by_hand: "Knot tied by hand", check_knot: "Knot checked", reload: "Slot reloaded" }[asked.ask];
if (!words || !asked.button.label.startsWith(words)) fail(`button '${asked.button.label}' for a ${asked.ask} request`);
if (!asked.asked || !asked.asked.startsWith("Weaver: ")) fail(`the request is not shown beside its button: ${JSON.stringify(asked)}`);
await screenshot(page);
await evaluate(page, `document.querySelector('button[data-cmd="next"]').click()`);
const answered = await waitFor("the panel's answer accepted", v => v.reply.startsWith("ok next"), 20);
console.log(`PASS: the heads asked '${asked.asked}' (${asked.ask}); the page offered "${asked.button.label}"; ` +
  `pressed: "${answered.reply}"; screenshot ${pngPath}`);
browser.close();
process.exit(0);
