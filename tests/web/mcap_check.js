// crane_topic record --mcap read by independent readers (issue 16): npm's @mcap/core (its stream
// reader, CRCs validated, and its indexed reader for the summary), and Foxglove's ROS 2 decoding
// (@foxglove/rosmsg parses the channel's ros2msg schema, @foxglove/rosmsg2-serialization decodes
// the CDR). tests/web/foxglove_client_test.sh installs them into a test-local folder (NODE_PATH).
//
//   node mcap_check.js RUN.mcap RUN.csv.samples.jsonl DURATION_S
//
// The same crane_topic record wrote both files from the same samples (--mcap and --out), so every
// message must decode to the JSON line of the same topic, header.seq and header.stamp (1e-9).
// Exits 1 unless: profile ros2; one channel per topic of the bus (>= 10), message encoding cdr,
// schema encoding ros2msg named crane_msgs/msg/<Type>, offered_qos_profiles in its metadata;
// /crane/hw/sensors holds 100 Hz x DURATION_S +- 2 % messages; the summary's statistics agree.
"use strict";
const fs = require("fs");
const { McapStreamReader, McapIndexedReader } = require("@mcap/core");
const { parse } = require("@foxglove/rosmsg");
const { MessageReader } = require("@foxglove/rosmsg2-serialization");

const [file, recordedPath, durationText] = process.argv.slice(2);
const duration = Number(durationText);
const TOLERANCE = 1e-9;

function plain(value) {
  if (typeof value === "bigint") return Number(value);
  if (ArrayBuffer.isView(value)) return Array.from(value, plain);
  if (Array.isArray(value)) return value.map(plain);
  if (value !== null && typeof value === "object") {
    const out = {};
    // ROS 2 decoders give builtin_interfaces/Time as {sec, nsec}; the IDL's field is nanosec.
    for (const [k, v] of Object.entries(value)) out[k === "nsec" ? "nanosec" : k] = plain(v);
    return out;
  }
  return value;
}

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
  if (a && b && typeof a === "object" && typeof b === "object") {
    let m = 0;
    for (const k of new Set([...Object.keys(a), ...Object.keys(b)])) {
      if (!(k in a) || !(k in b)) {
        mismatches.push(`${path}.${k}: only in ${k in a ? "MCAP" : "the JSON record"}`);
        return Infinity;
      }
      m = Math.max(m, difference(a[k], b[k], `${path}.${k}`, mismatches));
    }
    return m;
  }
  mismatches.push(`${path}: ${JSON.stringify(a)} vs ${JSON.stringify(b)}`);
  return Infinity;
}

async function main() {
  const bytes = fs.readFileSync(file);
  const problems = [];
  const recorded = new Map();
  for (const line of fs.readFileSync(recordedPath, "utf8").split("\n")) {
    if (!line) continue;
    const r = JSON.parse(line);
    const h = r.sample.header;
    recorded.set(`${r.topic}|${h.seq}|${h.stamp.sec}|${h.stamp.nanosec}`, r.sample);
  }

  // 1. Stream reader: every record in order, CRCs checked.
  const reader = new McapStreamReader({ validateCrcs: true });
  reader.append(new Uint8Array(bytes.buffer, bytes.byteOffset, bytes.byteLength));
  let header = null;
  const schemas = new Map();
  const channels = new Map();
  const perChannel = new Map();
  let worst = 0;
  const mismatches = [];
  let unmatched = 0;
  let decodeFailures = 0;
  for (let record; (record = reader.nextRecord()); ) {
    if (record.type === "Header") header = record;
    else if (record.type === "Schema") schemas.set(record.id, record);
    else if (record.type === "Channel" && !channels.has(record.id)) {  // the summary repeats them
      const schema = schemas.get(record.schemaId);
      const text = new TextDecoder().decode(schema.data);
      channels.set(record.id, { ...record, schema, decoder: new MessageReader(parse(text, { ros2: true })) });
      perChannel.set(record.id, 0);
    } else if (record.type === "Message") {
      const channel = channels.get(record.channelId);
      perChannel.set(record.channelId, perChannel.get(record.channelId) + 1);
      let sample;
      try {
        sample = plain(channel.decoder.readMessage(record.data));
      } catch (e) {
        if (++decodeFailures < 5) problems.push(`${channel.topic}: cannot decode: ${e.message}`);
        continue;
      }
      const h = sample.header;
      const twin = recorded.get(`rt${channel.topic}|${h.seq}|${h.stamp.sec}|${h.stamp.nanosec}`);
      if (twin === undefined) {
        unmatched += 1;
        continue;
      }
      worst = Math.max(worst, difference(sample, twin, channel.topic, mismatches));
    }
  }
  if (!reader.done()) problems.push("the stream reader did not reach the end magic");

  // 2. Indexed reader: the summary (schemas, channels, statistics) read from the footer backwards.
  const indexed = await McapIndexedReader.Initialize({
    readable: {
      size: async () => BigInt(bytes.byteLength),
      read: async (offset, size) => new Uint8Array(bytes.buffer, bytes.byteOffset + Number(offset), Number(size)),
    },
  });
  const stats = indexed.statistics;
  const streamTotal = [...perChannel.values()].reduce((a, b) => a + b, 0);

  const sensors = [...channels.values()].find((c) => c.topic === "/crane/hw/sensors");
  const sensorCount = sensors ? perChannel.get(sensors.id) : 0;
  const expected = 100 * duration;
  const summary = {
    profile: header && header.profile,
    library: header && header.library,
    channels: [...channels.values()].map((c) => ({ topic: c.topic, schema: c.schema.name, schema_encoding: c.schema.encoding,
                                                   message_encoding: c.messageEncoding, messages: perChannel.get(c.id) })),
    messages: streamTotal,
    sensor_messages: sensorCount,
    sensor_messages_expected: `${expected} +- 2 %`,
    statistics: stats && { message_count: Number(stats.messageCount), channel_count: stats.channelCount,
                           schema_count: stats.schemaCount },
    decode_failures: decodeFailures,
    without_json_twin: unmatched,
    max_abs_difference: worst,
    mismatches: mismatches.slice(0, 10),
  };
  const expect = (ok, what) => ok || problems.push(what);
  expect(header && header.profile === "ros2", `profile ${header && header.profile}, expected ros2`);
  expect(channels.size >= 10, `${channels.size} channels`);
  for (const c of channels.values()) {
    expect(c.messageEncoding === "cdr", `${c.topic}: message encoding ${c.messageEncoding}`);
    expect(c.schema.encoding === "ros2msg", `${c.topic}: schema encoding ${c.schema.encoding}`);
    expect(/^crane_msgs\/msg\/[A-Za-z]+$/.test(c.schema.name), `${c.topic}: schema name ${c.schema.name}`);
    expect(c.metadata.has("offered_qos_profiles"), `${c.topic}: no offered_qos_profiles`);
  }
  expect(Math.abs(sensorCount - expected) <= 0.02 * expected, `${sensorCount} sensor messages, expected ${expected} +- 2 %`);
  expect(stats !== undefined && Number(stats.messageCount) === streamTotal, "statistics disagree with the messages");
  expect(indexed.channelsById.size === channels.size, "summary channels disagree");
  expect(decodeFailures === 0 && unmatched === 0 && mismatches.length === 0 && worst <= TOLERANCE,
         "decoded messages differ from the JSON record");
  summary.problems = problems;
  console.log(JSON.stringify(summary, null, 1));
  process.exit(problems.length === 0 ? 0 : 1);
}

main().catch((e) => {
  console.error(e);
  process.exit(1);
});
