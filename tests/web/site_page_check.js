// crane_web's site page (deploy/web/www/site.html) and its view (/site/view.json) against other
// computations (tests/web/site_page_test.sh runs it):
//   1. the view: every crane of the site reported, the site service heard, one pair per two cranes;
//   2. each pair's distance equals what crane_site_status (another process on the site's domain)
//      prints for it, and is no more than this file's own bound from the parts the view gives:
//      the closest of points sampled along each two capsules' axes (to an upright part's cylinder),
//      less the radii; who waits for whom, why and since when, as crane_site_status says it (the
//      writer's tc1 waits);
//   3. the site's scene for Foxglove's 3D panel, as Foxglove's own client (@foxglove/ws-protocol)
//      receives it: a JSON foxglove.SceneUpdate with an entity per crane whose load cylinder is
//      the view's load envelope, a line loop per box the view holds and asks for, and a text per
//      pair naming the view's distance;
//   4. the page in Debian's chromium, headless (puppeteer-core): it drew every crane (its load's
//      pixel in the crane's colour, not the background), the held and requested airspace the view
//      has, a row per pair coloured by its band, the service's epoch; a screenshot.
//
//   node site_page_check.js URL SCREENSHOT.png CRANE_SITE_STATUS SITE_FILE
// Exit 1 on a difference.
"use strict";
const puppeteer = require("puppeteer-core");
const { FoxgloveClient } = require("@foxglove/ws-protocol");
const WebSocket = require("ws");
const http = require("http");
const { execFileSync } = require("child_process");
const fs = require("fs");
const os = require("os");
const path = require("path");

const [url, screenshot, statusTool, siteFile] = process.argv.slice(2);
const httpUrl = url.replace(/^ws:/, "http:");

function getJson(p) {
  return new Promise((resolve, reject) => {
    http.get(httpUrl + p, { agent: false }, (res) => {
      let body = "";
      res.on("data", (d) => (body += d));
      res.on("end", () => (res.statusCode === 200 ? resolve(JSON.parse(body)) : reject(new Error(`${p}: HTTP ${res.statusCode}`))));
    }).on("error", reject);
  });
}

const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
const sub = (a, b) => a.map((v, i) => v - b[i]);
const norm = (a) => Math.hypot(...a);

// The smallest distance between points sampled along the two axes (an upper bound of the
// segments' distance: the capsules' distance can only be smaller), less both radii. An upright
// part (the cable's and the load's envelope: a cylinder with flat ends) is taken as what it is:
// each sampled point's distance to the solid cylinder, its plan distance to the axis less the
// radius and its height outside the cylinder's, by Pythagoras.
function toUpright(x, u) {
  const plan = Math.hypot(x[0] - u.a[0], x[1] - u.a[1]) - u.radius;
  const gap = Math.max(0, x[2] - Math.max(u.a[2], u.b[2]), Math.min(u.a[2], u.b[2]) - x[2]);
  return gap > 0 ? Math.hypot(Math.max(0, plan), gap) : plan;
}
function sampledDistance(p, q) {
  let best = Infinity;
  const n = 200;
  const along = (s, i) => s.a.map((v, k) => v + (s.b[k] - v) * (i / n));
  if (p.upright && q.upright) {
    // Points of p's axis against q's cylinder, less p's radius: p's cylinder holds every point
    // within its radius of the axis in plan, at the axis' heights.
    for (let i = 0; i <= n; ++i) {
      const x = along(p, i);
      const plan = Math.hypot(x[0] - q.a[0], x[1] - q.a[1]) - q.radius - p.radius;
      const gap = Math.max(0, x[2] - Math.max(q.a[2], q.b[2]), Math.min(q.a[2], q.b[2]) - x[2]);
      best = Math.min(best, gap > 0 ? Math.hypot(Math.max(0, plan), gap) : plan);
    }
    return best;
  }
  if (p.upright || q.upright) {
    const [u, c] = p.upright ? [p, q] : [q, p];
    for (let i = 0; i <= n; ++i) best = Math.min(best, toUpright(along(c, i), u));
    return best - c.radius;
  }
  for (let i = 0; i <= n; ++i) {
    const a = along(p, i);
    for (let j = 0; j <= n; ++j) best = Math.min(best, norm(sub(a, along(q, j))));
  }
  return best - p.radius - q.radius;
}

async function main() {
  const problems = [];
  // 1. The view, once everything was heard.
  let view = null;
  for (let k = 0; k < 100; ++k) {
    view = await getJson("/site/view.json").catch(() => null);
    if (view && view.service && view.cranes.every((c) => c.state !== "silent") &&
        view.pairs.length === (view.cranes.length * (view.cranes.length - 1)) / 2) break;
    await sleep(200);
  }
  if (!view || !view.service) throw new Error("no view with the service heard: " + JSON.stringify(view));
  const n = view.cranes.length;
  if (n < 2) problems.push(`${n} cranes in the view`);
  for (const c of view.cranes) if (c.state === "silent") problems.push(`${c.name} not heard`);
  console.log(`[ figure ] site page view: ${n} cranes (${view.cranes.map((c) => c.name + " " + c.holding).join(", ")}), ` +
              `${view.pairs.length} pairs, service epoch ${view.service.epoch}`);

  // 2. The distances: crane_site_status's, and a bound of this file's own.
  const out = path.join(os.tmpdir(), `site_status_${process.pid}.json`);
  execFileSync(statusTool, ["--site", siteFile, "--wait", "2", "--json", out], { stdio: ["ignore", "inherit", "inherit"] });
  const status = JSON.parse(fs.readFileSync(out, "utf8"));
  fs.unlinkSync(out);
  const byName = Object.fromEntries(view.cranes.map((c) => [c.name, c]));
  for (const p of view.pairs) {
    const name = p.cranes.join("-");
    const theirs = status.pairs.find((q) => q.cranes === name);
    if (!theirs) { problems.push(`crane_site_status has no pair ${name}`); continue; }
    if (Math.abs(theirs.distance_m - p.distance) > 1e-9) {
      problems.push(`${name}: the view's ${p.distance} m, crane_site_status's ${theirs.distance_m} m`);
    }
    let bound = Infinity;
    for (const a of byName[p.cranes[0]].parts) for (const b of byName[p.cranes[1]].parts) bound = Math.min(bound, sampledDistance(a, b));
    if (!(p.distance <= bound + 1e-9)) problems.push(`${name}: the view's ${p.distance} m exceeds the sampled parts' ${bound} m`);
    if (p.distance < bound - 0.01) problems.push(`${name}: the view's ${p.distance} m is far below the sampled parts' ${bound} m`);
    const band = p.distance < view.margins.stop ? "stop" : p.distance < view.margins.slow_down ? "slow_down"
               : p.distance < view.margins.warning ? "warning" : "clear";
    if (band !== p.band) problems.push(`${name}: band ${p.band}, by the margins ${band}`);
    console.log(`[ figure ] ${name}: ${p.distance.toFixed(4)} m (${p.parts.join("-")}), crane_site_status ` +
                `${theirs.distance_m.toFixed(4)} m, sampled parts ${bound.toFixed(4)} m, band ${p.band}`);
  }
  // Who waits, why and since when: a reason exactly when it waits for a crane, a time exactly when
  // its request is pending, the same as crane_site_status's (a later status: the writer's cranes
  // stand still, so the waits stay; the time only grows).
  const waiting = view.cranes.filter((c) => c.waits_for.length > 0);
  if (waiting.length === 0) problems.push("no crane waits in the view: the writer's tc1 asks for a leg through the others");
  for (const c of view.cranes) {
    const theirs = status.cranes.find((q) => q.name === c.name);
    if ((c.waits_for.length > 0) !== (c.wait_reason !== null)) problems.push(`${c.name}: waits for [${c.waits_for}], reason ${c.wait_reason}`);
    if (c.waiting !== (c.waited_s !== null) || (c.waited_s !== null && !(c.waited_s >= 0))) {
      problems.push(`${c.name}: waiting ${c.waiting}, waited ${c.waited_s} s`);
    }
    if (!theirs) { problems.push(`crane_site_status has no crane ${c.name}`); continue; }
    if ((c.wait_reason || "-") !== theirs.why || (c.waits_for.join(",") || "-") !== theirs.waits_for) {
      problems.push(`${c.name}: the view's wait for [${c.waits_for}] (${c.wait_reason}), crane_site_status's ${theirs.waits_for} (${theirs.why})`);
    }
    // Its work left, as it reports it (the writer's --work: tc1 123.4 s, tc3 56.7 s, tc2 none).
    const work = { tc1: 123.4, tc2: 0, tc3: 56.7 }[c.name];
    if (c.work_left_s !== work || theirs.work_left_s !== work) {
      problems.push(`${c.name}: work left ${c.work_left_s} s in the view, ${theirs.work_left_s} s in crane_site_status's, written ${work} s`);
    }
    if (c.waited_s !== null && !(theirs.waited_s >= c.waited_s)) {
      problems.push(`${c.name}: waited ${c.waited_s} s in the view, ${theirs.waited_s} s in crane_site_status's later status`);
    }
  }
  console.log(`[ figure ] site page waits: ${waiting.map((c) => `${c.name} for ${c.waits_for} (${c.wait_reason}, ${c.waited_s.toFixed(1)} s)`).join("; ")}`);

  // 3. The scene, as Foxglove's client gets it (the view fetched again right after: the cranes
  // stand still, so both describe the same site).
  const scene = await new Promise((resolve, reject) => {
    const client = new FoxgloveClient({ ws: new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]) });
    const timer = setTimeout(() => { client.close(); reject(new Error("no /site/scene message within 10 s")); }, 10000);
    let subscription = null;
    client.on("advertise", (channels) => {
      const ch = channels.find((c) => c.topic === "/site/scene");
      if (!ch) return;
      if (ch.encoding !== "json" || ch.schemaName !== "foxglove.SceneUpdate" || ch.schemaEncoding !== "jsonschema") {
        problems.push(`/site/scene advertised as ${ch.encoding} ${ch.schemaName} ${ch.schemaEncoding}`);
      }
      JSON.parse(ch.schema);  // a JSON schema that parses
      subscription = client.subscribe(ch.id);
    });
    client.on("message", ({ subscriptionId, data }) => {
      if (subscriptionId !== subscription) return;
      clearTimeout(timer);
      client.close();
      resolve(JSON.parse(new TextDecoder().decode(data)));
    });
  });
  const now = await getJson("/site/view.json");
  for (const c of now.cranes) {
    const e = scene.entities.find((x) => x.id === "crane/" + c.name);
    if (!e) { problems.push(`scene: no entity for ${c.name}`); continue; }
    if (e.frame_id !== "site") problems.push(`scene: ${c.name} in frame ${e.frame_id}`);
    // The load's envelope: an upright cylinder over the view's load part, as wide and as tall.
    const load = c.parts.find((p) => p.part === "load");
    const cylinder = e.cylinders.find((y) => Math.abs(y.pose.position.x - load.a[0]) < 1e-9 &&
                                             Math.abs(y.pose.position.y - load.a[1]) < 1e-9 &&
                                             Math.abs(y.size.x - 2 * load.radius) < 1e-9);
    if (!load.upright || !cylinder || Math.abs(cylinder.size.z - Math.abs(load.b[2] - load.a[2])) > 1e-9 ||
        Math.abs(cylinder.pose.position.z - (load.a[2] + load.b[2]) / 2) > 1e-9) {
      problems.push(`scene: ${c.name}'s load cylinder ${JSON.stringify(cylinder)} is not the view's load ${JSON.stringify(load)}`);
    }
    const loops = e.lines.filter((l) => l.type === 1).length;
    if (loops !== c.held.length + c.requested.length) {
      problems.push(`scene: ${c.name} has ${loops} line loops, the view ${c.held.length} held + ${c.requested.length} requested boxes`);
    }
    const label = (e.texts[0] || { text: "" }).text;
    const waits = c.waits_for.length > 0 ? `waits for ${c.waits_for.join(", ")} (${c.wait_reason}, ` : null;
    if (waits !== null && !label.includes(waits)) problems.push(`scene: ${c.name}'s text '${label}' does not say '${waits}...'`);
  }
  const texts = (scene.entities.find((x) => x.id === "site/distances") || { texts: [] }).texts.map((t) => t.text);
  for (const p of now.pairs) {
    const words = `${p.cranes.join("-")} ${p.distance.toFixed(3)} m`;
    if (!texts.some((t) => t.startsWith(words))) problems.push(`scene: no text '${words}' among ${JSON.stringify(texts)}`);
  }
  console.log(`[ figure ] site scene over Foxglove's client: ${scene.entities.length} entities, ` +
              `${scene.entities.reduce((n, e) => n + e.lines.length, 0)} lines, distances ${JSON.stringify(texts)}`);

  // 4. The page.
  const browser = await puppeteer.launch({
    executablePath: "/usr/bin/chromium",
    headless: true,
    args: ["--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage"],
  });
  try {
    const page = await browser.newPage();
    await page.setViewport({ width: 1400, height: 800 });
    const errors = [];
    page.on("pageerror", (e) => errors.push(String(e)));
    await page.goto(httpUrl + "/site.html", { waitUntil: "load", timeout: 20000 });
    await page.waitForFunction(() => window.siteView && window.siteView.views >= 3 && window.siteView.drawn, { timeout: 20000 });
    const seen = await page.evaluate(() => {
      const s = window.siteView;
      s.draw();
      const ctx = document.getElementById("plan").getContext("2d");
      const pixel = (p) => Array.from(ctx.getImageData(Math.round(p[0]), Math.round(p[1]), 1, 1).data);
      return {
        cranes: s.drawn.cranes.map((c) => ({ name: c.name, held: c.held, requested: c.requested, load: c.load_px && pixel(c.load_px) })),
        view: s.view,
        rows: Array.from(document.querySelectorAll("#pairs tr")).slice(1).map((tr) => tr.className),
        craneRows: document.querySelectorAll("#cranes tr").length - 1,
        workCells: Array.from(document.querySelectorAll("#cranes tr")).slice(1).map((tr) => tr.children[9] && tr.children[9].textContent),
        service: document.getElementById("service").textContent,
      };
    });
    if (errors.length) problems.push("page errors: " + errors.join("; "));
    if (seen.cranes.length !== n) problems.push(`the page drew ${seen.cranes.length} cranes of ${n}`);
    seen.cranes.forEach((c, i) => {
      const v = seen.view.cranes[i];
      if (!c.load) problems.push(`${c.name}: no load drawn`);
      else if (c.load[3] < 200 || (c.load[0] > 240 && c.load[1] > 240 && c.load[2] > 240)) {
        problems.push(`${c.name}: its load's pixel is background (${c.load})`);
      }
      if (c.held !== v.held.length || c.requested !== v.requested.length) {
        problems.push(`${c.name}: drew ${c.held} held and ${c.requested} requested boxes, the view has ${v.held.length} and ${v.requested.length}`);
      }
    });
    const asked = seen.view.cranes.filter((c) => c.requested.length > 0 || c.holding === "path");
    if (asked.length === 0) problems.push("no crane asks for or holds a path: the test's --ask was not seen");
    if (seen.craneRows !== n) problems.push(`${seen.craneRows} crane rows`);
    if (seen.workCells.join(",") !== "123.4,0.0,56.7") problems.push(`the crane rows' work left: ${seen.workCells.join(", ")}`);
    if (seen.rows.length !== seen.view.pairs.length || seen.rows.some((c, i) => c !== seen.view.pairs[i].band)) {
      problems.push(`pair rows ${JSON.stringify(seen.rows)} against bands ${JSON.stringify(seen.view.pairs.map((p) => p.band))}`);
    }
    if (!seen.service.includes("epoch " + seen.view.service.epoch)) problems.push(`status line '${seen.service}'`);
    console.log(`[ figure ] site page: ${seen.cranes.length} cranes drawn (${seen.cranes.map((c) => `${c.name} held ${c.held} requested ${c.requested}`).join(", ")}), ` +
                `${seen.rows.length} pair rows (${seen.rows.join(", ")}), '${seen.service}'`);
    await page.screenshot({ path: screenshot, fullPage: true });
  } finally {
    await browser.close();
  }
  if (problems.length) {
    for (const p of problems) console.log("FAIL: " + p);
    process.exit(1);
  }
  console.log("site page: every check passed");
}

main().catch((e) => { console.error(e); process.exit(1); });
