// crane_web's operator page in a real browser (issue 16): Debian's chromium, headless, driven by
// npm's puppeteer-core over the DevTools protocol (tests/web/foxglove_client_test.sh installs it).
//
//   node page_check.js URL SCREENSHOT.png ZONE_COMMAND...
//
// Loads http://HOST:PORT/ (the page speaks the Foxglove protocol back to the same server), waits
// until it has decoded 300 sensor samples, and checks what it shows against an independent decoder:
// the page's last sensor sample (decoded by its own IDL/CDR code, crane_view.js) equals the same
// bytes decoded by Foxglove's @foxglove/omgidl-serialization with the advertised schema; the mode
// is a name of the IDL's MODE_ codes; the views and plots are drawn (non-blank canvases). Then the
// no-go zones of /site.json (the server's --config; at least one, the first off as configured):
// drawn in the top view as off (a faint grey fill at the zone's centre); then `ZONE_COMMAND enable
// 0` (crane_safety) switches the first on in the supervisor, and the page, from the supervisor's
// status, draws it enforced (red) and names it in the status line. Writes a screenshot with it
// enforced (and leaves it on). Exit 1 on a difference.
"use strict";
const puppeteer = require("puppeteer-core");
const { parseIDL } = require("@foxglove/omgidl-parser");
const { MessageReader } = require("@foxglove/omgidl-serialization");
const http = require("http");

const [url, screenshot, ...zoneCommand] = process.argv.slice(2);
const { execFileSync } = require("child_process");

function getJson(path) {
  return new Promise((resolve, reject) => {
    http.get(url.replace(/^ws:/, "http:") + path, { agent: false }, (res) => {
      let body = "";
      res.on("data", (d) => (body += d));
      res.on("end", () => (res.statusCode === 200 ? resolve(JSON.parse(body)) : reject(new Error(`${path}: HTTP ${res.statusCode}`))));
    }).on("error", reject);
  });
}

// The top view's pixel at the first zone's centre after drawing a frame, and how the page drew it.
function firstZone(page) {
  return page.evaluate(() => {
    window.craneView.draw();
    const z = window.craneView.zonesDrawn[0];
    const d = document.getElementById("top").getContext("2d").getImageData(z.centre_px[0], z.centre_px[1], 1, 1).data;
    return { ...z, pixel_rgba: Array.from(d), status_line: document.getElementById("zones").textContent };
  });
}
// Enforced: the red fill (alpha 0.35 over the transparent canvas); off: the faint grey (alpha 0.10).
const looksEnforced = (z) => z.pixel_rgba[3] > 60 && z.pixel_rgba[0] > 150 && z.pixel_rgba[1] < 120;
const looksOff = (z) => z.pixel_rgba[3] > 0 && z.pixel_rgba[3] < 60;
const httpUrl = url.replace(/^ws:/, "http:") + "/";

function plain(value) {
  if (typeof value === "bigint") return Number(value);
  if (ArrayBuffer.isView(value)) return Array.from(value, plain);
  if (Array.isArray(value)) return value.map(plain);
  if (value !== null && typeof value === "object") return Object.fromEntries(Object.entries(value).map(([k, v]) => [k, plain(v)]));
  return value;
}

async function main() {
  const browser = await puppeteer.launch({
    executablePath: "/usr/bin/chromium",
    headless: true,
    args: ["--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage"],
  });
  const problems = [];
  try {
    const page = await browser.newPage();
    await page.setViewport({ width: 1080, height: 800 });
    const errors = [];
    page.on("pageerror", (e) => errors.push(String(e)));
    await page.goto(httpUrl, { waitUntil: "load", timeout: 20000 });
    await page.waitForFunction(() => window.craneView && window.craneView.sensors >= 300 && window.craneView.mode &&
                                     window.craneView.site && window.craneView.status, { timeout: 20000 });
    // One synchronous task: draw a frame from the samples so far, then read what it shows (a new
    // sample is another task and cannot come in between; headless chromium may throttle the
    // animation frames themselves).
    const shown = await page.evaluate(() => (window.craneView.draw(), {
      sensors: window.craneView.sensors, last: window.craneView.last, payload: window.craneView.lastPayload,
      mode: window.craneView.mode, faults: window.craneView.faults,
      blank: ["top", "side", "plot_positions", "plot_swing", "plot_voltages"].filter((id) => {
        const c = document.getElementById(id);
        const d = c.getContext("2d").getImageData(0, 0, c.width, c.height).data;
        return !d.some((v, i) => i % 4 === 3 && v !== 0);
      }),
      values: document.getElementById("values").textContent,
    }));
    // The site: the page's geometry is the server's /site.json; its first zone drawn off, then enforced.
    const site = await getJson("/site.json");
    const pageSite = await page.evaluate(() => window.craneView.site);
    const zoneOff = await firstZone(page);
    let zoneOn = null;
    if (JSON.stringify(site) !== JSON.stringify(pageSite)) problems.push("the page's site is not /site.json");
    if (!site.zones || site.zones.length === 0) {
      problems.push("the configuration has no no-go zone to draw");
    } else {
      if (site.zones[0].enabled_at_start) problems.push("the first zone is configured on: its off state is not checked");
      if (zoneOff.enabled || !looksOff(zoneOff)) problems.push(`zone 0 off: drawn ${JSON.stringify(zoneOff)}`);
      execFileSync(zoneCommand[0], [...zoneCommand.slice(1), "enable", "0"], { stdio: ["ignore", "ignore", "inherit"] });
      await page.waitForFunction(() => (window.craneView.draw(), window.craneView.zonesDrawn[0].enabled), { timeout: 5000 });
      zoneOn = await firstZone(page);
      if (!looksEnforced(zoneOn)) problems.push(`zone 0 enforced: drawn ${JSON.stringify(zoneOn)}`);
      if (!zoneOn.status_line.includes(site.zones[0].name)) problems.push(`status line "${zoneOn.status_line}" does not name zone 0`);
    }
    await page.screenshot({ path: screenshot, fullPage: true });
    // The same bytes through Foxglove's decoder, with the schema the server advertises.
    const advertised = await new Promise((resolve, reject) => {
      const WebSocket = require("ws");
      const ws = new WebSocket(url, ["foxglove.websocket.v1"]);
      ws.on("message", (d, binary) => {
        if (binary) return;
        const m = JSON.parse(d.toString());
        if (m.op === "advertise") { ws.terminate(); resolve(m.channels); }
      });
      ws.on("error", reject);
    });
    const sensors = advertised.find((c) => c.topic === "rt/crane/hw/sensors");
    const reference = plain(new MessageReader(sensors.schemaName, parseIDL(sensors.schema)).readMessage(Uint8Array.from(shown.payload)));
    const same = JSON.stringify(reference) === JSON.stringify(shown.last);
    const summary = { page_sensor_samples: shown.sensors, mode: shown.mode, faults: shown.faults, blank_canvases: shown.blank,
                      page_equals_foxglove_decoder: same, page_errors: errors, last_seq: shown.last.header.seq,
                      site: { source: site.source, kind: site.kind, zones: site.zones.length }, zone_off: zoneOff, zone_enforced: zoneOn };
    const modes = (sensors.schema.match(/MODE_[A-Z_]+/g) || []).map((m) => m.slice(5).toLowerCase());
    if (!same) problems.push(`page decoded ${JSON.stringify(shown.last)}, Foxglove ${JSON.stringify(reference)}`);
    if (!modes.includes(shown.mode)) problems.push(`mode '${shown.mode}' is not one of ${modes}`);
    if (shown.blank.length) problems.push(`blank canvases: ${shown.blank}`);
    if (errors.length) problems.push(`page errors: ${errors}`);
    const panelCycle = Number((shown.values.match(/cycle\s+(\d+)/) || [])[1]);
    if (panelCycle !== shown.last.header.seq) {
      problems.push(`the sample panel shows cycle ${panelCycle}, the last sample is ${shown.last.header.seq}`);
    }
    summary.problems = problems;
    console.log(JSON.stringify(summary, null, 1));
  } finally {
    await browser.close();
  }
  process.exit(problems.length === 0 ? 0 : 1);
}

main().catch((e) => {
  console.error(e);
  process.exit(1);
});
