// A minimal Chrome DevTools Protocol client over node's own WebSocket (no npm packages): launches
// headless Chromium with a throw-away profile, opens pages and evaluates expressions in them. Shared
// by the panel's browser tests.
import { spawn } from "node:child_process";
import { mkdtempSync, rmSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";

export const sleep = ms => new Promise(r => setTimeout(r, ms));

// Resolves to { send, open, evaluate, close }; `fail(msg)` is called (and should exit) when Chromium
// cannot be started.
export async function launch(chromiumBin, fail) {
  const profile = mkdtempSync(join(tmpdir(), "loom_panel_chromium."));
  const chrome = spawn(chromiumBin, [
    "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
    "--disable-background-networking", "--disable-component-update", "--disable-sync",
    "--disable-dev-shm-usage", `--user-data-dir=${profile}`, "--remote-debugging-port=0",
    "--remote-debugging-address=127.0.0.1", "--window-size=1200,1500", "about:blank"], { stdio: ["ignore", "ignore", "pipe"] });
  const close = () => {
    try { chrome.kill("SIGKILL"); } catch {}
    try { rmSync(profile, { recursive: true, force: true }); } catch {}
  };
  const wsUrl = await new Promise((resolve, reject) => {
    let err = "";
    chrome.stderr.on("data", d => {
      err += d;
      const m = err.match(/DevTools listening on (ws:\/\/\S+)/);
      if (m) resolve(m[1]);
    });
    chrome.on("exit", code => reject(new Error(`chromium exited ${code}: ${err.slice(-2000)}`)));
  }).catch(e => { close(); fail(e.message); });

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
  const open = async url => {
    const { targetId } = await send("Target.createTarget", { url });
    const { sessionId } = await send("Target.attachToTarget", { targetId, flatten: true });
    await send("Runtime.enable", {}, sessionId);
    return sessionId;
  };
  const evaluate = async (session, expression) => {
    const r = await send("Runtime.evaluate", { expression, returnByValue: true, awaitPromise: true }, session);
    return r.result.value;
  };
  return { send, open, evaluate, close: () => { try { ws.close(); } catch {} close(); } };
}

// The preamble every check shares. Its arguments are `<chromium> <panel base url> <loom id> <png> <timeout s>
// [more...]`; it sets an overall deadline (`timeout s`, else `defaultTimeoutS`) and launches Chromium.
// Returns { base, loomId, pngPath, rest (the further arguments), started (ms), fail, send, open, evaluate,
// close, waitFor, screenshot }:
//   fail(msg)  prints "FAIL: msg", closes the browser and exits 1;
//   waitFor(read, what, ok, seconds, everyMs = 200) polls `await read()` until ok(value) holds (a null
//              value never does) and returns that value, else fails naming `what` and the last value read;
//   screenshot(page, path = pngPath) writes the page as PNG.
export async function startCheck(defaultTimeoutS = 60) {
  const [chromiumBin, base, loomId, pngPath, timeoutArg, ...rest] = process.argv.slice(2);
  const started = Date.now();
  const timeoutMs = Number(timeoutArg || defaultTimeoutS) * 1000;
  let browser = null;
  const fail = msg => { console.error("FAIL: " + msg); browser?.close(); process.exit(1); };
  setTimeout(() => fail(`gave up after ${timeoutMs / 1000} s`), timeoutMs).unref();
  browser = await launch(chromiumBin, fail);
  const waitFor = async (read, what, ok, seconds, everyMs = 200) => {
    const until = Date.now() + seconds * 1000;
    let v = null;
    while (Date.now() < until) {
      v = await read();
      if (v !== null && v !== undefined && ok(v)) return v;
      await sleep(everyMs);
    }
    fail(`${what}: not seen within ${seconds} s (last DOM read ${JSON.stringify(v)})`);
  };
  const screenshot = async (page, path = pngPath) => {
    const shot = await browser.send("Page.captureScreenshot", { format: "png", captureBeyondViewport: true }, page);
    writeFileSync(path, Buffer.from(shot.data, "base64"));
  };
  return { ...browser, base, loomId, pngPath, rest, started, timeoutMs, fail, waitFor, screenshot };
}
