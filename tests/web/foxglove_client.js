// An independent Foxglove WebSocket client for crane_web (issue 16), built only from Foxglove's own
// npm packages: @foxglove/ws-protocol (the protocol client), @foxglove/omgidl-parser and
// @foxglove/omgidl-serialization (decode CDR with an OMG IDL schema, as Foxglove Studio does), ws.
// tests/web/foxglove_client_test.sh installs them into a test-local folder (NODE_PATH).
//
//   node foxglove_client.js live URL DECODED.jsonl SECONDS [MIN_CHANNELS]
//       connects (subprotocol foxglove.websocket.v1), lists the channels, subscribes to every one,
//       decodes every sample with its channel's advertised schema for SECONDS (after 1 s of warm-up:
//       the measured window starts 1 s after the first sensor sample), writes one line per
//       decoded sample {topic, receive_ns, sample}, prints a JSON summary (rate of
//       rt/crane/hw/sensors by arrival time, decode failures) and exits 1 when fewer than
//       MIN_CHANNELS channels were advertised, a sample failed to decode, or a channel is not cdr/omgidl.
//   node foxglove_client.js compare DECODED.jsonl RECORDED.jsonl
//       matches each decoded sample with crane_topic record's sample of the same topic, header.seq
//       and header.stamp, compares every field (numbers within 1e-9), prints a JSON summary and
//       exits 1 on a difference or when a decoded rt/crane/hw/sensors sample has no recorded twin.
//   node foxglove_client.js load URL CLIENTS SECONDS
//       CLIENTS connections subscribed to every channel for SECONDS (deploy/bench_web.sh).
//   node foxglove_client.js abuse URL SECONDS STALLED_CLOSE
//       bad input while a well-behaved client takes rt/crane/hw/sensors for SECONDS (or until 1 s
//       after the stalled client's close, at most SECONDS + 10): malformed JSON, an unknown channel
//       id, a binary frame, a 200 KiB frame, a handshake without the subprotocol, and a client
//       subscribed to everything that does not read until /metrics counts its close (crane_web
//       started with --close-stalled STALLED_CLOSE); checks each answer (error status, close 1009,
//       HTTP 400, and for the stalled client a close 1008 with its reason), that the good client
//       still gets 100 +- 5 Hz through all of it and stays open, and that /metrics counted it all
//       (refusals, dropped samples, the stalled close, samples received, rates, supervisor mode,
//       plant cycles).
"use strict";
const fs = require("fs");
const WebSocket = require("ws");
const { FoxgloveClient } = require("@foxglove/ws-protocol");
const { parseIDL } = require("@foxglove/omgidl-parser");
const { MessageReader } = require("@foxglove/omgidl-serialization");

const SENSORS = "rt/crane/hw/sensors";
const TOLERANCE = 1e-9;
const WARM_UP_MS = 1000;

// Decoded values as plain JSON: bigint (uint64, int64) to number, typed arrays to arrays.
function plain(value) {
  if (typeof value === "bigint") return Number(value);
  if (ArrayBuffer.isView(value)) return Array.from(value, plain);
  if (Array.isArray(value)) return value.map(plain);
  if (value !== null && typeof value === "object") {
    const out = {};
    for (const [k, v] of Object.entries(value)) out[k] = plain(v);
    return out;
  }
  return value;
}

function live(url, outPath, seconds, minChannels) {
  const out = fs.createWriteStream(outPath);
  const client = new FoxgloveClient({ ws: new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]) });
  const channels = new Map(); // subscription id -> {topic, reader}
  const problems = [];
  const counts = {};
  const sensorArrivals = [];
  let serverInfo = null;
  let decodeFailures = 0;
  let firstSensor = null;
  let started = null;
  let finished = false;
  const statuses = [];
  client.on("serverInfo", (info) => (serverInfo = info));
  client.on("status", (s) => statuses.push(s));
  client.on("error", (e) => problems.push(`connection error: ${e}`));
  client.on("advertise", (advertised) => {
    // Every schema parsed first, then the subscriptions: parsing blocks this event loop, and
    // samples that queue meanwhile would arrive in a burst.
    const ready = [];
    for (const ch of advertised) {
      if (ch.encoding !== "cdr" || ch.schemaEncoding !== "omgidl") {
        problems.push(`${ch.topic}: encoding ${ch.encoding}, schemaEncoding ${ch.schemaEncoding}`);
        continue;
      }
      ready.push({ ch, reader: new MessageReader(ch.schemaName, parseIDL(ch.schema)) });
    }
    for (const { ch, reader } of ready) {
      channels.set(client.subscribe(ch.id), { topic: ch.topic, reader, schemaName: ch.schemaName });
    }
  });
  client.on("message", ({ subscriptionId, timestamp, data }) => {
    const now = process.hrtime.bigint();
    const ch = channels.get(subscriptionId);
    if (ch === undefined) return problems.push(`message on unknown subscription ${subscriptionId}`);
    let sample;
    try {
      sample = ch.reader.readMessage(new Uint8Array(data.buffer, data.byteOffset, data.byteLength));
    } catch (e) {
      decodeFailures += 1;
      if (decodeFailures < 5) problems.push(`${ch.topic}: cannot decode with ${ch.schemaName}: ${e.message}`);
      return;
    }
    // The measured window: SECONDS from the first sensor sample after a 1 s warm-up.
    if (ch.topic === SENSORS && firstSensor === null) {
      firstSensor = now;
      setTimeout(() => {
        started = process.hrtime.bigint();
        setTimeout(finish, seconds * 1000);
      }, WARM_UP_MS);
    }
    if (started === null || finished) return;
    if (ch.topic === SENSORS) sensorArrivals.push(Number(now - started) * 1e-9);
    counts[ch.topic] = (counts[ch.topic] || 0) + 1;
    out.write(JSON.stringify({ topic: ch.topic, receive_ns: timestamp.toString(), sample: plain(sample) }) + "\n");
  });
  function finish() {
    finished = true;
    client.close();
    const n = sensorArrivals.length;
    const span = n > 1 ? sensorArrivals[n - 1] - sensorArrivals[0] : 0;
    const summary = {
      server: serverInfo && { name: serverInfo.name, capabilities: serverInfo.capabilities, metadata: serverInfo.metadata },
      channels: [...channels.values()].map((c) => `${c.topic} (${c.schemaName})`),
      seconds,
      sensor_samples: n,
      sensor_rate_hz: n / seconds,
      sensor_rate_between_first_and_last_hz: span > 0 ? (n - 1) / span : 0,
      samples_per_topic: counts,
      decode_failures: decodeFailures,
      error_statuses: statuses.filter((s) => s.level === 2).map((s) => s.message),
      problems,
    };
    out.end(() => {
      console.log(JSON.stringify(summary, null, 1));
      const ok = channels.size >= minChannels && decodeFailures === 0 && problems.length === 0 && n > 0 &&
        summary.error_statuses.length === 0 && serverInfo !== null && !serverInfo.capabilities.includes("clientPublish");
      process.exit(ok ? 0 : 1);
    });
  }
  setTimeout(() => {
    if (started === null) {
      console.log(JSON.stringify({ error: `no ${SENSORS} sample within 20 s`, channels: channels.size, problems }));
      process.exit(1);
    }
  }, 20000);
}

function key(topic, sample) {
  const h = sample.header;
  return `${topic}|${h.seq}|${h.stamp.sec}|${h.stamp.nanosec}`;
}

// Largest |difference| between two decoded values; Infinity on a structural mismatch.
function difference(a, b, path, mismatches) {
  if (typeof a === "number" && typeof b === "number") return Math.abs(a - b);
  if (typeof a === "boolean" || typeof b === "boolean") {
    if (a === b) return 0;
    mismatches.push(`${path}: ${a} vs ${b}`);
    return Infinity;
  }
  if (Array.isArray(a) && Array.isArray(b) && a.length === b.length) {
    return a.reduce((m, v, i) => Math.max(m, difference(v, b[i], `${path}[${i}]`, mismatches)), 0);
  }
  if (a && b && typeof a === "object" && typeof b === "object" && !Array.isArray(a) && !Array.isArray(b)) {
    const keys = new Set([...Object.keys(a), ...Object.keys(b)]);
    let m = 0;
    for (const k of keys) {
      if (!(k in a) || !(k in b)) {
        mismatches.push(`${path}.${k}: only in ${k in a ? "decoded" : "recorded"}`);
        return Infinity;
      }
      m = Math.max(m, difference(a[k], b[k], `${path}.${k}`, mismatches));
    }
    return m;
  }
  mismatches.push(`${path}: ${JSON.stringify(a)} vs ${JSON.stringify(b)}`);
  return Infinity;
}

function compare(decodedPath, recordedPath) {
  const recorded = new Map();
  for (const line of fs.readFileSync(recordedPath, "utf8").split("\n")) {
    if (!line) continue;
    const r = JSON.parse(line);
    recorded.set(key(r.topic, r.sample), r.sample);
  }
  const perTopic = {};
  let worst = 0;
  const mismatches = [];
  for (const line of fs.readFileSync(decodedPath, "utf8").split("\n")) {
    if (!line) continue;
    const d = JSON.parse(line);
    const t = (perTopic[d.topic] = perTopic[d.topic] || { decoded: 0, matched: 0, max_abs_difference: 0 });
    t.decoded += 1;
    const twin = recorded.get(key(d.topic, d.sample));
    if (twin === undefined) continue;
    t.matched += 1;
    const diff = difference(d.sample, twin, d.topic, mismatches);
    t.max_abs_difference = Math.max(t.max_abs_difference, diff);
    worst = Math.max(worst, diff);
  }
  const sensors = perTopic[SENSORS] || { decoded: 0, matched: 0 };
  const summary = { recorded_samples: recorded.size, per_topic: perTopic, max_abs_difference: worst,
                    mismatches: mismatches.slice(0, 10) };
  console.log(JSON.stringify(summary, null, 1));
  const ok = sensors.decoded > 0 && sensors.matched === sensors.decoded && worst <= TOLERANCE && mismatches.length === 0;
  process.exit(ok ? 0 : 1);
}

// ---- bad input and /metrics ----------------------------------------------------------------

// GET http://HOST:PORT/metrics -> Map "name{labels}" -> value (Prometheus text format).
function scrape(url) {
  const http = require("http");
  return new Promise((resolve, reject) => {
    // agent false: a fresh connection per request (crane_web closes each HTTP connection after its answer).
    http.get(url.replace(/^ws:/, "http:") + "/metrics", { agent: false }, (res) => {
      let body = "";
      res.on("data", (d) => (body += d));
      res.on("end", () => {
        if (res.statusCode !== 200) return reject(new Error(`/metrics: HTTP ${res.statusCode}`));
        if (!/text\/plain; version=0\.0\.4/.test(res.headers["content-type"])) {
          return reject(new Error(`/metrics: content type ${res.headers["content-type"]}`));
        }
        const values = new Map();
        for (const line of body.split("\n")) {
          if (!line || line.startsWith("#")) continue;
          const cut = line.lastIndexOf(" ");
          values.set(line.slice(0, cut), Number(line.slice(cut + 1)));
        }
        resolve(values);
      });
    }).on("error", reject);
  });
}

const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

// A raw ws client of the protocol; resolves with it once open. statuses/close are recorded.
function rawClient(url, protocols = [FoxgloveClient.SUPPORTED_SUBPROTOCOL]) {
  const ws = new WebSocket(url, protocols);
  const state = { ws, statuses: [], advertised: [], closeCode: null, binaryFrames: 0, refused: null };
  ws.on("message", (data, isBinary) => {
    if (isBinary) return void (state.binaryFrames += 1);
    const m = JSON.parse(data.toString());
    if (m.op === "status") state.statuses.push(m);
    if (m.op === "advertise") state.advertised.push(...m.channels);
  });
  ws.on("close", (code) => (state.closeCode = code));
  ws.on("unexpected-response", (req, res) => (state.refused = res.statusCode));
  ws.on("error", () => {});
  return new Promise((resolve) => {
    ws.on("open", () => resolve(state));
    ws.on("unexpected-response", () => resolve(state));
  });
}

async function abuse(url, seconds, stalledClose) {
  const before = await scrape(url);
  const problems = [];
  // A client subscribed to every channel that does not read (stalled_client.py: its receive buffer
  // is fixed small, so the server's queue for it fills within seconds) until told to, after the
  // window: then it reads what the server sent it, the close frame last.
  const { spawn } = require("child_process");
  const readline = require("readline");
  const [host, port] = url.replace(/^ws:\/\//, "").split(":");
  const stalled = spawn("python3", [require("path").join(__dirname, "stalled_client.py"), host, port, String(seconds + 30)],
                        { stdio: ["pipe", "pipe", "inherit"] });
  const stalledLines = readline.createInterface({ input: stalled.stdout })[Symbol.asyncIterator]();
  const stalledChannels = Number((await stalledLines.next()).value);
  const stalledStart = Date.now();

  // A well-behaved client on rt/crane/hw/sensors through all of it.
  const good = await rawClient(url);
  await sleep(300);
  const sensors = good.advertised.find((c) => c.topic === SENSORS);
  good.ws.send(JSON.stringify({ op: "subscribe", subscriptions: [{ id: 1, channelId: sensors.id }] }));
  // The offenders.
  const malformed = await rawClient(url);
  malformed.ws.send("{not json");
  const unknown = await rawClient(url);
  unknown.ws.send(JSON.stringify({ op: "subscribe", subscriptions: [{ id: 1, channelId: 99999 }] }));
  const binary = await rawClient(url);
  binary.ws.send(Buffer.from(Array.from({ length: 200 }, (_, i) => (i * 37 + 11) & 0xff)));
  const oversized = await rawClient(url);
  oversized.ws.send("x".repeat(200 * 1024));
  const wrongProtocol = await rawClient(url, ["not.foxglove"]);
  const start = good.binaryFrames;
  const t0 = Date.now();
  // The window: SECONDS, longer if need be so that it takes in the stalled client's close and 1 s
  // after it (at most 10 s more); /metrics polled for that close meanwhile.
  const STALLED_CLOSED = "crane_web_stalled_clients_closed_total";
  let stalledClosedAfter = null;  // [s] since the stalled client subscribed
  const windowOver = () => {
    const elapsed = Date.now() - t0;
    if (elapsed >= (seconds + 10) * 1000) return true;
    if (stalledClosedAfter === null) return false;
    return elapsed >= seconds * 1000 && Date.now() - stalledStart >= (stalledClosedAfter + 1) * 1000;
  };
  while (!windowOver()) {
    await sleep(250);
    if (stalledClosedAfter === null && ((await scrape(url)).get(STALLED_CLOSED) || 0) > (before.get(STALLED_CLOSED) || 0)) {
      stalledClosedAfter = (Date.now() - stalledStart) / 1000;
      // It reads now, within the closing handshake's time (websocketpp ends the connection 5 s
      // after its close frame when no answer came): the samples on their way, then the close frame.
      stalled.stdin.write("read now\n");
    }
  }
  const windowEnd = Date.now();
  const goodRate = ((good.binaryFrames - start) * 1000) / (windowEnd - t0);
  const after = await scrape(url);
  // What the stalled client read once closed: the data before the close, then close 1008 and its
  // reason (told to read at the window's end if it was never closed).
  if (stalledClosedAfter === null) stalled.stdin.write("read now\n");
  const stalledEnd = JSON.parse((await stalledLines.next()).value || "{}");
  const delta = (k) => (after.get(k) || 0) - (before.get(k) || 0);
  const summary = {
    window_s: (windowEnd - t0) / 1000,
    good_client_sensor_rate_hz: goodRate,
    good_client_close_code: good.closeCode,
    stalled_client_closed_after_s: stalledClosedAfter,
    stalled_client_end: stalledEnd,
    malformed_status: malformed.statuses.map((s) => s.message),
    unknown_channel_status: unknown.statuses.map((s) => s.message),
    binary_status: binary.statuses.map((s) => s.message),
    oversized_close_code: oversized.closeCode,
    wrong_protocol_http_status: wrongProtocol.refused,
    metrics_delta: {
      refused_request: delta('crane_web_requests_refused_total{kind="request"}'),
      refused_binary: delta('crane_web_requests_refused_total{kind="binary"}'),
      refused_handshake: delta('crane_web_requests_refused_total{kind="handshake"}'),
      refused_oversized: delta('crane_web_requests_refused_total{kind="oversized"}'),
      samples_dropped: delta("crane_web_samples_dropped_total"),
      stalled_clients_closed: delta(STALLED_CLOSED),
      sensors_received: delta(`crane_topic_samples_received_total{topic="${SENSORS}"}`),
    },
    metrics_after: {
      clients: after.get("crane_web_clients"),
      sensor_rate_hz: after.get(`crane_topic_rate_hz{topic="${SENSORS}"}`),
      supervisor_mode: [...after].filter(([k, v]) => k.startsWith("crane_supervisor_mode{") && v === 1).map(([k]) => k),
      plant_cycles: after.get('crane_process_cycles{process="plant"}'),
      plant_overruns: after.get('crane_process_overruns{process="plant"}'),
      plant_latency_p99_us: after.get('crane_process_latency_us{process="plant",quantile="0.99"}'),
      faults_raised: after.get("crane_supervisor_faults_raised"),
    },
  };
  const expect = (ok, what) => ok || problems.push(what);
  expect(goodRate >= 95 && goodRate <= 105, `good client got ${goodRate} Hz, not 100 +- 5`);
  expect(summary.malformed_status.some((m) => m.startsWith("malformed JSON")), "no error status for malformed JSON");
  expect(summary.unknown_channel_status.some((m) => m.includes("unknown channel id 99999")), "no error for the unknown channel");
  expect(summary.binary_status.some((m) => m.includes("client publishing")), "no error status for a binary frame");
  // The server closes with 1009; the client may see the reset first (1006) while its 200 KiB are
  // still being written: either way that connection is closed, and the metrics name the cause.
  expect(oversized.closeCode === 1009 || oversized.closeCode === 1006,
         `oversized frame: close code ${oversized.closeCode}, expected 1009 (or 1006)`);
  expect(wrongProtocol.refused === 400, `handshake without the subprotocol: HTTP ${wrongProtocol.refused}, expected 400`);
  const d = summary.metrics_delta;
  expect(d.refused_request >= 2 && d.refused_binary >= 1 && d.refused_handshake >= 1 && d.refused_oversized >= 1,
         "refusals not counted");
  expect(stalledChannels >= 10, `the stalled client subscribed to ${stalledChannels} channels`);
  expect(d.samples_dropped > 0, "the stalled client's queue dropped nothing");
  // Closed after --close-stalled of drops (its queue fills first), within the good client's window,
  // with 1008 and the reason; counted once; the good client still open.
  expect(d.stalled_clients_closed === 1, `${STALLED_CLOSED} grew by ${d.stalled_clients_closed}, expected 1`);
  expect(stalledClosedAfter !== null && stalledClosedAfter >= stalledClose,
         `the stalled client was closed ${stalledClosedAfter} s after it subscribed (--close-stalled ${stalledClose} s)`);
  expect(stalledEnd.close_code === 1008 && /^not reading: every sample dropped for/.test(stalledEnd.close_reason) &&
         stalledEnd.eof === true, `the stalled client read ${JSON.stringify(stalledEnd)}, expected close 1008 "not reading..."`);
  expect(good.closeCode === null, `the good client was closed (${good.closeCode})`);
  expect(d.sensors_received >= 95 * seconds, `sensors received grew by ${d.sensors_received} only`);
  const a = summary.metrics_after;
  expect(a.sensor_rate_hz >= 90 && a.sensor_rate_hz <= 110, `crane_topic_rate_hz of the sensors ${a.sensor_rate_hz}`);
  expect(a.supervisor_mode.length === 1, "not exactly one supervisor mode at 1");
  expect(a.plant_cycles > 0, "no plant cycles in the metrics");
  expect(a.clients >= 4, `crane_web_clients ${a.clients}`);
  summary.problems = problems;
  console.log(JSON.stringify(summary, null, 1));
  for (const c of [good, malformed, unknown, binary]) c.ws.terminate();
  stalled.kill();
  process.exit(problems.length === 0 ? 0 : 1);
}

// ---- load: N clients subscribed to every channel ---------------------------------------------

// Opens `clients` connections, each subscribed to every advertised channel, reads for `seconds`,
// prints {clients, seconds, frames per client (min, max), bytes} and exits 0 (deploy/bench_web.sh).
async function load(url, clients, seconds) {
  const all = [];
  for (let i = 0; i < clients; ++i) {
    const c = await rawClient(url);
    for (let k = 0; k < 50 && c.advertised.length === 0; ++k) await sleep(20);
    c.ws.send(JSON.stringify({ op: "subscribe", subscriptions: c.advertised.map((ch, j) => ({ id: j, channelId: ch.id })) }));
    c.bytes = 0;
    c.ws.on("message", (data) => (c.bytes += data.length));
    all.push(c);
  }
  console.error(`load: ${clients} clients subscribed to ${all[0].advertised.length} channels each`);
  await sleep(seconds * 1000);
  const frames = all.map((c) => c.binaryFrames);
  console.log(JSON.stringify({ clients, seconds, frames_per_client_min: Math.min(...frames),
                               frames_per_client_max: Math.max(...frames),
                               bytes_total: all.reduce((a, c) => a + c.bytes, 0) }));
  for (const c of all) c.ws.terminate();
  process.exit(0);
}

const [mode, ...args] = process.argv.slice(2);
if (mode === "live") live(args[0], args[1], Number(args[2]), Number(args[3] || 10));
else if (mode === "compare") compare(args[0], args[1]);
else if (mode === "load") load(args[0], Number(args[1]), Number(args[2])).catch((e) => { console.error(e); process.exit(1); });
else if (mode === "abuse") abuse(args[0], Number(args[1]), Number(args[2])).catch((e) => { console.error(e); process.exit(1); });
else {
  console.error("usage: foxglove_client.js live URL OUT.jsonl SECONDS [MIN_CHANNELS] | compare DECODED.jsonl RECORDED.jsonl");
  process.exit(2);
}
