// The job queue's buttons on the loom's page (issue 29), read and pressed as a weaver would:
//   1. unpaired: the queue lists job 1 with Start over and Remove disabled, the Add job form disabled;
//      POSTs forced from the page (add, remove, start-over) are refused by the panel (403, "not paired");
//   2. a path typed into the form survives the page's live re-renders;
//   3. paired through the page's pairing field: the buttons enabled; once job 1 is carpet_done (woven at the
//      machine), Add job (the design and 2 rows) shows the loom's "ok job add: job 2" and job 2 queued;
//      Remove on job 2 asks to be pressed again (nothing sent at the first press), then job 2 leaves the
//      queue; Start over on job 1 shows "ok job start-over" and job 1 queued at 0 rows again.
// Usage: node --experimental-websocket panel_jobs.mjs <chromium> <panel base url> <loom id> <png>
//        <timeout s> <pairing code> <design path>
import { startCheck } from "./cdp.mjs";

const browser = await startCheck(80);
const { base, loomId, pngPath, rest, fail, open, evaluate, screenshot } = browser;
const [pairCode, design] = rest;

const page = await open(`${base}/loom/${loomId}`);
const read = () => evaluate(page, `(() => {
  const q = document.getElementById("job-queue");
  if (!q) return null;
  const add = document.getElementById("job-add-button");
  return {
    paired: !document.getElementById("pair-code"),
    queue: [...q.querySelectorAll("tr[data-job]")].map(r => ({ id: Number(r.dataset.job), state: r.dataset.state,
      rows: r.children[2].textContent,
      buttons: [...r.querySelectorAll("button[data-job-verb]")].map(b => [b.dataset.jobVerb, b.disabled, b.textContent]) })),
    addDisabled: add ? add.disabled : null, designValue: document.getElementById("job-design")?.value ?? null,
    reply: document.getElementById("job-reply")?.textContent ?? "", marked: !!document.getElementById("jobs").dataset.mark };
})()`);
const waitFor = (what, ok, seconds) => browser.waitFor(read, what, ok, seconds, 100);
const job = (v, id) => v.queue.find(q => q.id === id);
const click = sel => evaluate(page, `document.querySelector(${JSON.stringify(sel)}).click()`);

// 1. Unpaired.
const a = await waitFor("job 1 in the queue with its buttons", v => job(v, 1) && job(v, 1).buttons.length === 2 && v.addDisabled !== null, 30);
if (a.paired) fail("the page is paired before the pairing code was entered");
if (!job(a, 1).buttons.every(b => b[1]) || !a.addDisabled) fail(`unpaired, a job button is enabled: ${JSON.stringify(a)}`);
const forced = await evaluate(page, `(async () => {
  const out = [];
  for (const [verb, body] of [["add", "design=" + encodeURIComponent(${JSON.stringify(design)})], ["remove", "id=1"], ["start-over", "id=1"]]) {
    const r = await fetch("/api/loom/${loomId}/job/" + verb, { method: "POST", body: new URLSearchParams(body),
      headers: { "X-Loom-Panel": "1", "X-Loom-Device": device } });
    out.push([verb, r.status, (await r.json()).reply]);
  }
  return out;
})()`);
for (const [verb, status, reply] of forced) {
  if (status !== 403 || !reply.startsWith(`refused: job ${verb}: this device is not paired`)) {
    fail(`unpaired ${verb} forced: ${status} "${reply}"`);
  }
}

// 2. A path being typed is kept across the live re-renders (the loom is weaving: updates come every 0.25 s).
await evaluate(page, `(() => { document.getElementById("job-design").value = "/typed/path.csv";
  document.getElementById("jobs").dataset.mark = "1"; })()`);
const kept = await waitFor("the page rendered again", v => !v.marked, 20);
if (kept.designValue !== "/typed/path.csv") fail(`the typed path was lost in a re-render: "${kept.designValue}"`);

// 3. Paired.
await evaluate(page, `(() => { document.getElementById("pair-code").value = "${pairCode}";
  document.querySelector('button[data-pair]').click(); })()`);
await waitFor("the page paired with its job buttons enabled", v => v.paired && !v.addDisabled && job(v, 1) && job(v, 1).buttons.every(b => !b[1]), 20);
const done = await waitFor("job 1 carpet_done (woven at the machine)", v => job(v, 1) && job(v, 1).state === "carpet_done", 60);

await evaluate(page, `(() => { document.getElementById("job-design").value = ${JSON.stringify(design)};
  document.getElementById("job-length-kind").value = "rows"; document.getElementById("job-length").value = "2"; })()`);
await click("#job-add-button");
const added = await waitFor("job 2 added and queued", v => v.reply.startsWith("ok job add: job 2: rug.csv") && job(v, 2) && job(v, 2).state === "queued", 20);
if (job(added, 2).rows !== "0 / 2") fail(`job 2 shows rows "${job(added, 2).rows}", want "0 / 2"`);

await click('button[data-job-verb="remove"][data-job-id="2"]');
const asking = await waitFor("Remove asking to be pressed again", v => job(v, 2) && job(v, 2).buttons.some(b => b[0] === "remove" && /Press again/.test(b[2])), 10);
if (asking.reply !== added.reply) fail(`the first press of Remove sent something: "${asking.reply}"`);
await click('button[data-job-verb="remove"][data-job-id="2"]');
const removed = await waitFor("job 2 removed", v => v.reply.startsWith("ok job remove: job 2 removed") && !job(v, 2), 20);

await click('button[data-job-verb="start-over"][data-job-id="1"]');
await waitFor("Start over asking to be pressed again", v => job(v, 1).buttons.some(b => b[0] === "start-over" && /Press again/.test(b[2])), 10);
await click('button[data-job-verb="start-over"][data-job-id="1"]');
const over = await waitFor("job 1 started over", v => v.reply.startsWith("ok job start-over: job 1 starts over at row 1") &&
  job(v, 1).state === "queued" && job(v, 1).rows === "0 / 1", 20);
await screenshot(page);
console.log(`PASS: unpaired: buttons disabled, forced POSTs ${JSON.stringify(forced.map(f => [f[0], f[1]]))}; ` +
  `paired: job 1 ${done.queue[0].state} -> "${added.reply}" -> "${removed.reply}" -> "${over.reply}"; queue ` +
  `${JSON.stringify(over.queue.map(q => [q.id, q.state, q.rows]))}; screenshot ${pngPath}`);
browser.close();
process.exit(0);
