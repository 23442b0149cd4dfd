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

const [mode, ...args] = process.argv.slice(2);
if (mode === "live") live(args[0], args[1], Number(args[2]), Number(args[3] || 10));
else if (mode === "compare") compare(args[0], args[1]);
else {
  console.error("usage: foxglove_client.js live URL OUT.jsonl SECONDS [MIN_CHANNELS] | compare DECODED.jsonl RECORDED.jsonl");
  process.exit(2);
}
