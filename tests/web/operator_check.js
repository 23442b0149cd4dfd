// The operator page's controls in a real browser (issue 16): Debian's chromium, headless, driven by
// npm's puppeteer-core (tests/web/foxglove_client_test.sh installs it), against crane_web started
// with --operators and the live simulated stack.
//
//   node operator_check.js URL TOKEN SCREENSHOT.png
//
// 1. Without logging in, the page is read-only: its controls are inert, a "move to" called in the
//    page is refused (nothing is published) and the trolley does not move.
// 2. A Foxglove client without the session (the ws module, no cookie) is refused client publishing:
//    its advertise and its binary goal are answered with errors; one with the operator's cookie but
//    another page's Origin is refused too.
// 3. A wrong token is refused; the right one logs in; the page reconnects as the operator, types
//    the targets, presses "move to", and the trolley and slew arrive (the planner's move status
//    "arrived" for that request, then the measured trolley within 5 mm and the slew within 0.5 deg
//    of the targets).
// Prints a JSON summary; exit 1 on a failed check.
"use strict";
const puppeteer = require("puppeteer-core");
const http = require("http");
const WebSocket = require("ws");

const [url, token, screenshot] = process.argv.slice(2);
const httpUrl = url.replace(/^ws:/, "http:");
const TARGET_TROLLEY = 0.5, TARGET_SLEW_DEG = 20;

function post(path, body, headers = {}) {
  return new Promise((resolve, reject) => {
    // agent false: a fresh connection per request (crane_web closes each HTTP connection after its answer).
    const req = http.request(httpUrl + path, { method: "POST", agent: false, headers: { "Content-Length": Buffer.byteLength(body), ...headers } }, (res) => {
      let data = "";
      res.on("data", (c) => (data += c));
      res.on("end", () => resolve({ status: res.statusCode, cookie: (res.headers["set-cookie"] || [""])[0].split(";")[0], body: data }));
    });
    req.on("error", reject);
    req.end(body);
  });
}

// What a plain Foxglove client gets when it tries to publish a goal: serverInfo's capabilities and
// the server's status messages.
function tryPublishing(headers) {
  return new Promise((resolve, reject) => {
    const ws = new WebSocket(url, ["foxglove.websocket.v1"], { headers });
    const seen = { capabilities: null, errors: [] };
    ws.on("message", (d, binary) => {
      if (binary) return;
      const m = JSON.parse(d.toString());
      if (m.op === "serverInfo") seen.capabilities = m.capabilities;
      if (m.op === "status") seen.errors.push(m.message);
      if (m.op === "advertise") {
        ws.send(JSON.stringify({ op: "advertise", channels: [{ id: 1, topic: "rt/crane/planner/goal", encoding: "cdr" }] }));
        ws.send(Buffer.from([1, 1, 0, 0, 0, 0, 1, 0, 0, 42]));
        setTimeout(() => { ws.terminate(); resolve(seen); }, 1000);
      }
    });
    ws.on("error", reject);
  });
}

async function main() {
  const problems = [];
  const summary = {};
  const browser = await puppeteer.launch({ executablePath: "/usr/bin/chromium", headless: true,
                                          args: ["--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage"] });
  try {
    const page = await browser.newPage();
    await page.setViewport({ width: 1080, height: 1000 });
    const errors = [];
    page.on("pageerror", (e) => errors.push(String(e)));
    await page.goto(httpUrl + "/", { waitUntil: "load", timeout: 20000 });
    await page.waitForFunction(() => window.craneView && window.craneView.sensors >= 50 && window.craneView.mode, { timeout: 20000 });
    // 1. Read-only: the page refuses to publish.
    const before = await page.evaluate(() => window.craneView.last.trolley_position);
    await page.click("#move"); // the read-only page's controls are inert
    const refusal = await page.evaluate(() => {
      try { window.craneView.controls.moveTo(0.9, 45, 0); return "published"; } catch (e) { return String(e.message); }
    });
    await new Promise((r) => setTimeout(r, 1500));
    const after = await page.evaluate(() => ({ x: window.craneView.last.trolley_position, sent: window.craneView.sent.length }));
    summary.read_only = { refusal, sent: after.sent, trolley_moved_mm: Math.abs(after.x - before) * 1e3 };
    if (!/log in as an operator/.test(refusal)) problems.push(`read-only page: moveTo gave "${refusal}"`);
    if (after.sent !== 0) problems.push("the read-only page published something");
    if (Math.abs(after.x - before) > 0.002) problems.push(`the trolley moved ${(after.x - before) * 1e3} mm without an operator`);

    // 2. Foxglove clients without the operator's session, and with it from another origin.
    const anonymous = await tryPublishing({});
    summary.anonymous_client = anonymous;
    if ((anonymous.capabilities || []).includes("clientPublish")) problems.push("an anonymous client was offered clientPublish");
    if (!anonymous.errors.some((e) => /client publishing is off/.test(e))) problems.push(`anonymous client errors: ${anonymous.errors}`);
    const wrong = await post("/login", "0".repeat(64));
    summary.wrong_token_status = wrong.status;
    if (wrong.status !== 403) problems.push(`a wrong token got HTTP ${wrong.status}`);
    const right = await post("/login", token);
    if (right.status !== 200 || !right.cookie) problems.push(`the operator's token got HTTP ${right.status}`);
    const foreign = await tryPublishing({ Cookie: right.cookie, Origin: "http://evil.example" });
    summary.foreign_origin_client = foreign;
    if ((foreign.capabilities || []).includes("clientPublish")) problems.push("a foreign origin was offered clientPublish");

    // 3. The operator logs in on the page and presses "move to".
    await page.type("#token", token);
    await page.click("#login");
    await page.waitForFunction(() => window.craneView.operator !== "" && window.craneView.connected, { timeout: 10000 });
    summary.operator = await page.evaluate(() => window.craneView.operator);
    await page.waitForFunction(() => window.craneView.sensors > 0 && window.craneView.status, { timeout: 10000 });
    await page.$eval("#target_trolley", (e, v) => (e.value = String(v)), TARGET_TROLLEY);
    await page.$eval("#target_slew", (e, v) => (e.value = String(v)), TARGET_SLEW_DEG);
    await page.$eval("#target_cable", (e) => (e.value = "0"));
    const pressed = Date.now();
    await page.click("#move");
    const sent = await page.evaluate(() => window.craneView.sent[window.craneView.sent.length - 1]);
    summary.sent = sent;
    await page.waitForFunction((id) => window.craneView.moveStatus && window.craneView.moveStatus.request_id === id &&
                                       ["arrived", "rejected", "aborted"].includes(window.craneView.moveStatus.result),
                               { timeout: 30000 }, sent.request_id);
    summary.move_status = await page.evaluate(() => window.craneView.moveStatus);
    if (summary.move_status.result !== "arrived") problems.push(`the move ended ${JSON.stringify(summary.move_status)}`);
    // The load settles after the reference arrives: the measured positions within 5 mm and 0.5 deg,
    // and staying there for 1 s (100 sensor cycles).
    await page.waitForFunction((x, deg) => {
      const s = window.craneView.last;
      const inside = Math.abs(s.trolley_position - x) < 0.005 && Math.abs(s.slew_angle * 180 / Math.PI - deg) < 0.5;
      window.settledSince = inside ? (window.settledSince ?? s.header.seq) : undefined;
      return inside && s.header.seq - window.settledSince >= 100;
    }, { timeout: 30000, polling: 10 }, TARGET_TROLLEY, TARGET_SLEW_DEG).catch(() => {});
    const last = await page.evaluate(() => (window.craneView.draw(), window.craneView.last));
    summary.arrived_after_s = (Date.now() - pressed) / 1000;
    summary.trolley_error_mm = (last.trolley_position - TARGET_TROLLEY) * 1e3;
    summary.slew_error_deg = last.slew_angle * 180 / Math.PI - TARGET_SLEW_DEG;
    if (Math.abs(summary.trolley_error_mm) >= 5) problems.push(`trolley ${summary.trolley_error_mm} mm from the target`);
    if (Math.abs(summary.slew_error_deg) >= 0.5) problems.push(`slew ${summary.slew_error_deg} deg from the target`);
    await page.screenshot({ path: screenshot, fullPage: true });
    summary.page_errors = errors;
    if (errors.length) problems.push(`page errors: ${errors}`);
  } finally {
    await browser.close();
  }
  summary.problems = problems;
  console.log(JSON.stringify(summary, null, 1));
  process.exit(problems.length ? 1 : 0);
}

main().catch((e) => { console.error(e); process.exit(1); });
