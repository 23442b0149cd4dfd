// crane_web's operator page: a Foxglove WebSocket client (foxglove.websocket.v1) that decodes the
// CDR samples with the OMG IDL schema the server advertises. The field names, the mode and fault
// names and the command codes come from that schema (the IDL's constants), not from this file.
// Read-only until an operator logs in (POST /login with the token; the server sets a session cookie
// and announces clientPublish on the next connection): then the controls publish goals and
// supervisor commands as CDR, encoded with the same schema (Foxglove client publishing). The views
// are drawn to the crane and the no-go zones of /site.json (the server's --config).
"use strict";

// ---- OMG IDL, the subset of idl/crane_msgs.idl: modules, @annotations, const, struct, arrays ----
function parseIdl(text) {
  const tokens = text.replace(/\/\*[\s\S]*?\*\//g, " ").replace(/\/\/[^\n]*/g, " ")
    .match(/::|[A-Za-z_][A-Za-z0-9_]*|-?[0-9][0-9.eE+-]*|[{}();:\[\]=@,<>]/g) || [];
  let i = 0;
  const structs = new Map(); // scoped name -> {fields: [{name, type, size}], scope}
  const constants = new Map(); // scoped module name -> [{name, value}]
  const next = () => tokens[i++];
  const skipAnnotation = () => {
    next(); // name
    if (tokens[i] === "(") { let depth = 0; do { const t = next(); if (t === "(") depth++; if (t === ")") depth--; } while (depth > 0); }
  };
  const scopedName = () => { let n = next(); while (tokens[i] === "::") { next(); n += "::" + next(); } return n; };
  function definitions(scope) {
    while (i < tokens.length && tokens[i] !== "}") {
      const t = next();
      if (t === "@") skipAnnotation();
      else if (t === "module") {
        const name = next(); next(); // {
        definitions([...scope, name]); next(); if (tokens[i] === ";") next();
      } else if (t === "const") {
        next(); const name = next(); next(); // type name =
        const value = Number(next()); next();
        const key = scope.join("::");
        if (!constants.has(key)) constants.set(key, []);
        constants.get(key).push({ name, value });
      } else if (t === "struct") {
        const name = next(); next(); // {
        const fields = [];
        while (tokens[i] !== "}") {
          if (tokens[i] === "@") { next(); skipAnnotation(); continue; }
          const type = scopedName(); const fname = next(); let size = 0;
          if (tokens[i] === "[") { next(); size = Number(next()); next(); }
          next(); // ;
          fields.push({ name: fname, type, size });
        }
        next(); if (tokens[i] === ";") next();
        structs.set([...scope, name].join("::"), { fields, scope });
      } else if (t === ";") { /* stray */ }
      else throw new Error(`IDL: unexpected '${t}'`);
    }
  }
  definitions([]);
  // A field's type in a scope: the innermost enclosing module that has it (IDL's scoping rule).
  const resolve = (type, scope) => {
    for (let n = scope.length; n >= 0; --n) {
      const candidate = [...scope.slice(0, n), type].join("::");
      if (structs.has(candidate)) return candidate;
    }
    return type;
  };
  for (const s of structs.values()) for (const f of s.fields) f.resolved = resolve(f.type, s.scope);
  return { structs, constants };
}

// ---- CDR (XCDR1, little or big endian per the encapsulation header), alignment from byte 4 ----
const PRIMITIVES = {
  boolean: [1, (v, o, le) => v.getUint8(o) !== 0], octet: [1, (v, o) => v.getUint8(o)], char: [1, (v, o) => v.getUint8(o)],
  int8: [1, (v, o) => v.getInt8(o)], uint8: [1, (v, o) => v.getUint8(o)],
  int16: [2, (v, o, le) => v.getInt16(o, le)], uint16: [2, (v, o, le) => v.getUint16(o, le)],
  int32: [4, (v, o, le) => v.getInt32(o, le)], uint32: [4, (v, o, le) => v.getUint32(o, le)],
  float: [4, (v, o, le) => v.getFloat32(o, le)], double: [8, (v, o, le) => v.getFloat64(o, le)],
  int64: [8, (v, o, le) => Number(v.getBigInt64(o, le))], uint64: [8, (v, o, le) => Number(v.getBigUint64(o, le))],
};
function decodeCdr(idl, typeName, view) {
  const le = (view.getUint8(1) & 1) === 1;
  let offset = 4;
  const read = (type) => {
    const p = PRIMITIVES[type];
    if (p) {
      offset += (p[0] - ((offset - 4) % p[0])) % p[0];
      const value = p[1](view, offset, le);
      offset += p[0];
      return value;
    }
    const s = idl.structs.get(type);
    if (!s) throw new Error(`CDR: unknown type ${type}`);
    const out = {};
    for (const f of s.fields) {
      out[f.name] = f.size ? Array.from({ length: f.size }, () => read(f.resolved)) : read(f.resolved);
    }
    return out;
  };
  return read(typeName);
}

// The inverse of decodeCdr: XCDR1 little endian (encapsulation 0x0001), fields missing from
// `value` written as 0. Returns the bytes.
function encodeCdr(idl, typeName, value) {
  const bytes = [0x00, 0x01, 0x00, 0x00];
  const scratch = new DataView(new ArrayBuffer(8));
  const WRITERS = {
    boolean: (v) => scratch.setUint8(0, v ? 1 : 0), octet: (v) => scratch.setUint8(0, v), char: (v) => scratch.setUint8(0, v),
    int8: (v) => scratch.setInt8(0, v), uint8: (v) => scratch.setUint8(0, v),
    int16: (v) => scratch.setInt16(0, v, true), uint16: (v) => scratch.setUint16(0, v, true),
    int32: (v) => scratch.setInt32(0, v, true), uint32: (v) => scratch.setUint32(0, v, true),
    float: (v) => scratch.setFloat32(0, v, true), double: (v) => scratch.setFloat64(0, v, true),
    int64: (v) => scratch.setBigInt64(0, BigInt(Math.trunc(v)), true), uint64: (v) => scratch.setBigUint64(0, BigInt(Math.trunc(v)), true),
  };
  const write = (type, v) => {
    const p = PRIMITIVES[type];
    if (p) {
      while ((bytes.length - 4) % p[0] !== 0) bytes.push(0);
      WRITERS[type](v === undefined ? 0 : v);
      for (let k = 0; k < p[0]; ++k) bytes.push(scratch.getUint8(k));
      return;
    }
    const s = idl.structs.get(type);
    if (!s) throw new Error(`CDR: unknown type ${type}`);
    for (const f of s.fields) {
      const fv = v ? v[f.name] : undefined;
      if (f.size) for (let k = 0; k < f.size; ++k) write(f.resolved, fv ? fv[k] : undefined);
      else write(f.resolved, fv);
    }
  };
  write(typeName, value);
  return new Uint8Array(bytes);
}

// ---- the page ----
const view = { connected: false, sensors: 0, last: null, lastPayload: null, actuators: null, status: null, mode: "", faults: [],
               operator: "", moveStatus: null, sent: [], site: null, zonesEnabled: null, zonesDrawn: [] };
window.craneView = view; // read by tests/web/page_check.js
const history = []; // {t, x, gamma, phi, theta, ux, ugamma}
const channels = new Map(); // subscription id -> {topic, schemaName, idl}
const idlCache = new Map();
const $ = (id) => document.getElementById(id);

function codeNames(idl, module, group) {
  return (idl.constants.get(module) || []).filter((c) => c.name.startsWith(group + "_"))
    .map((c) => ({ name: c.name.slice(group.length + 1).toLowerCase(), value: c.value }));
}

// ---- the operator's controls: what an operator's connection may publish ----
const GOAL = "rt/crane/planner/goal", COMMAND = "rt/crane/safety/command";
const publishing = new Map(); // topic -> {id, schemaName, idl} of our advertised client channel
let socket = null;
let mayPublish = false;

// Request ids only increase (the planner and the supervisor ignore one not above the last they
// took): tenths of a second since 2025-01-01, as crane_move (deploy/launcher/src/move_main.cpp).
let lastRequestId = 0;
function freshRequestId() {
  lastRequestId = Math.max(lastRequestId + 1, Math.floor(Date.now() / 100) - 17356896000);
  return lastRequestId;
}
function constant(idl, module, name) {
  const c = (idl.constants.get(module) || []).find((k) => k.name === name);
  if (!c) throw new Error(`the schema has no ${module}::${name}`);
  return c.value;
}
function header() {
  const now = Date.now();
  const stamp = { sec: Math.floor(now / 1000), nanosec: (now % 1000) * 1e6 };
  return { stamp, seq: 0, origin: stamp };
}
function publish(topic, message) {
  const ch = channelFor(topic);
  const payload = encodeCdr(ch.idl, ch.schemaName, message);
  const frame = new Uint8Array(5 + payload.length);
  const dv = new DataView(frame.buffer);
  dv.setUint8(0, 1); // Client Message Data
  dv.setUint32(1, ch.id, true);
  frame.set(payload, 5);
  socket.send(frame);
  view.sent.push({ topic, request_id: message.request_id, command: message.command });
  return message.request_id;
}
function channelFor(topic) {
  const ch = publishing.get(topic);
  if (!socket || !ch) throw new Error(`not allowed to publish ${topic} (log in as an operator)`);
  return ch;
}
function supervisorCommand(name) {
  const ch = channelFor(COMMAND);
  const code = constant(ch.idl, "crane_msgs::msg::SupervisorCommand_Constants", "COMMAND_" + name);
  return publish(COMMAND, { header: header(), request_id: freshRequestId(), command: code });
}
function moveTo(trolley, slewDeg, cable) {
  const ch = channelFor(GOAL);
  const k = (n) => constant(ch.idl, "crane_msgs::msg::MoveRequest_Constants", n);
  const axes = k("AXIS_TROLLEY") | k("AXIS_SLEW") | (cable > 0 ? k("AXIS_HOIST") : 0);
  return publish(GOAL, { header: header(), request_id: freshRequestId(), profile: k("PROFILE_TRAPEZOID"), axes,
                         command: k("COMMAND_MOVE"), trolley_target: trolley, slew_target: slewDeg * Math.PI / 180,
                         cable_length_target: cable > 0 ? cable : (view.last ? view.last.cable_length : 1.0) });
}
function softStop() {
  const ch = channelFor(GOAL);
  return publish(GOAL, { header: header(), request_id: freshRequestId(),
                         command: constant(ch.idl, "crane_msgs::msg::MoveRequest_Constants", "COMMAND_STOP") });
}
view.controls = { supervisorCommand, moveTo, softStop }; // also driven by tests/web/page_check.js

async function login() {
  const response = await fetch("/login", { method: "POST", body: $("token").value, credentials: "same-origin" });
  const answer = await response.json();
  $("login_state").textContent = response.ok ? `logged in as ${answer.operator}` : `refused: ${answer.error}`;
  $("token").value = "";
  if (response.ok && socket) socket.close(); // reconnect: the new handshake carries the session
}
async function logout() {
  await fetch("/logout", { method: "POST", credentials: "same-origin" });
  if (socket) socket.close();
}
function wireControls() {
  $("login").onclick = login;
  $("logout").onclick = logout;
  const guarded = (f) => () => {
    try { f(); $("control_error").textContent = ""; } catch (e) { $("control_error").textContent = String(e.message || e); }
  };
  $("arm").onclick = guarded(() => supervisorCommand("ARM"));
  $("disarm").onclick = guarded(() => supervisorCommand("DISARM"));
  $("reset").onclick = guarded(() => supervisorCommand("RESET"));
  $("estop").onclick = guarded(() => supervisorCommand("EMERGENCY_STOP"));
  $("stop").onclick = guarded(softStop);
  $("move").onclick = guarded(() => {
    const numbers = ["target_trolley", "target_slew", "target_cable"].map((id) => Number($(id).value));
    if (numbers.some((v) => !Number.isFinite(v))) throw new Error("move to: every target must be a number");
    moveTo(...numbers);
  });
}

// The crane's kind, travel and no-go zones, from the configuration crane_web was given (/site.json,
// deploy/web/site_view.hpp): what the views are drawn to.
async function loadSite() {
  try {
    const response = await fetch("/site.json", { credentials: "same-origin" });
    if (!response.ok) throw new Error(`HTTP ${response.status}`);
    view.site = await response.json();
  } catch (e) {
    $("link").textContent = `no site geometry (/site.json: ${e.message || e}); retrying`;
    setTimeout(loadSite, 2000);
  }
}

function connect() {
  // The same host and port as the page, over TLS when the page came over TLS (a proxy in front).
  const ws = new WebSocket(`${location.protocol === "https:" ? "wss" : "ws"}://${location.host}/`, ["foxglove.websocket.v1"]);
  socket = ws;
  ws.binaryType = "arraybuffer";
  ws.onopen = () => { view.connected = true; $("link").textContent = "connected to " + location.host; };
  ws.onclose = () => {
    view.connected = false; mayPublish = false; publishing.clear(); view.operator = ""; socket = null;
    $("link").textContent = "disconnected; retrying"; setTimeout(connect, 1000);
  };
  ws.onmessage = (event) => {
    if (typeof event.data === "string") {
      const m = JSON.parse(event.data);
      if (m.op === "serverInfo") {
        mayPublish = (m.capabilities || []).includes("clientPublish");
        view.operator = mayPublish ? String((m.metadata || {}).clientPublish || "").replace(/^operator /, "") : "";
        return;
      }
      if (m.op === "status") { if (m.level >= 2) $("control_error").textContent = m.message; return; }
      if (m.op !== "advertise") return;
      const wanted = ["rt/crane/hw/sensors", "rt/crane/hw/actuators", "rt/crane/safety/status", "rt/crane/planner/move_status"];
      const subscriptions = [];
      const advertise = [];
      for (const ch of m.channels) {
        if (ch.schemaEncoding !== "omgidl") continue;
        if (!idlCache.has(ch.schema)) idlCache.set(ch.schema, parseIdl(ch.schema));
        if (mayPublish && (ch.topic === GOAL || ch.topic === COMMAND)) {
          const id = advertise.length + 1;
          publishing.set(ch.topic, { id, schemaName: ch.schemaName, idl: idlCache.get(ch.schema) });
          advertise.push({ id, topic: ch.topic, encoding: "cdr", schemaName: ch.schemaName });
        }
        if (!wanted.includes(ch.topic)) continue;
        const id = subscriptions.length;
        channels.set(id, { topic: ch.topic, schemaName: ch.schemaName, idl: idlCache.get(ch.schema) });
        subscriptions.push({ id, channelId: ch.id });
      }
      ws.send(JSON.stringify({ op: "subscribe", subscriptions }));
      if (advertise.length) ws.send(JSON.stringify({ op: "advertise", channels: advertise }));
      return;
    }
    const frame = new DataView(event.data);
    if (frame.getUint8(0) !== 1) return;
    const ch = channels.get(frame.getUint32(1, true));
    if (!ch) return;
    const payload = new DataView(event.data, 13);
    const sample = decodeCdr(ch.idl, ch.schemaName, payload);
    if (ch.topic === "rt/crane/hw/sensors") {
      view.sensors += 1;
      view.last = sample;
      view.lastPayload = Array.from(new Uint8Array(event.data, 13));
      history.push({ t: sample.header.seq * 0.01, x: sample.trolley_position, gamma: sample.slew_angle,
                     phi: sample.swing_in_plane * 180 / Math.PI, theta: sample.swing_out_of_plane * 180 / Math.PI,
                     ux: sample.applied_trolley_voltage, ugamma: sample.applied_slew_voltage });
      if (history.length > 1000) history.shift();
    } else if (ch.topic === "rt/crane/hw/actuators") {
      view.actuators = sample;
    } else if (ch.topic === "rt/crane/planner/move_status") {
      const module = "crane_msgs::msg::MoveStatus_Constants";
      const result = codeNames(ch.idl, module, "RESULT").find((c) => c.value === sample.result);
      const reason = codeNames(ch.idl, module, "REASON").find((c) => c.value === sample.reason);
      view.moveStatus = { request_id: sample.request_id, result: result ? result.name : String(sample.result),
                          reason: reason ? reason.name : String(sample.reason), trolley_to_go: sample.trolley_to_go,
                          value: sample.value, bound_min: sample.bound_min, bound_max: sample.bound_max };
    } else {
      view.status = sample;
      const module = "crane_msgs::msg::SupervisorStatus_Constants";
      const mode = codeNames(ch.idl, module, "MODE").find((c) => c.value === sample.mode);
      view.mode = mode ? mode.name : String(sample.mode);
      const operation = codeNames(ch.idl, module, "OPERATION").find((c) => c.value === sample.operating_mode);
      view.operation = operation ? operation.name : String(sample.operating_mode);
      view.zonesEnabled = sample.zones_enabled >>> 0;
      view.faults = codeNames(ch.idl, module, "FAULT").filter((c) => (sample.active_faults & c.value) !== 0).map((c) => c.name);
      view.warnings = codeNames(ch.idl, module, "WARNING").filter((c) => (sample.warnings & c.value) !== 0).map((c) => c.name);
    }
  };
}

// The site's zones with the state the supervisor enforces (its status's zones_enabled, bit i:
// zones[i]); the configured state until a status has come.
function zoneStates() {
  const zones = view.site ? view.site.zones : [];
  return zones.map((z) => ({ index: z.index, name: z.name, polygon: z.polygon, bottom: z.bottom, top: z.top,
                             enabled: view.zonesEnabled === null ? z.enabled_at_start : ((view.zonesEnabled >>> z.index) & 1) === 1 }));
}

// A uniform scale [px/m] fitting the box [x0, x1] x [y0, y1] (m) in the canvas with a margin, y up.
function fit(c, x0, x1, y0, y1, margin = 14) {
  const scale = Math.min((c.width - 2 * margin) / Math.max(x1 - x0, 1e-6), (c.height - 2 * margin) / Math.max(y1 - y0, 1e-6));
  const ox = c.width / 2 - scale * (x0 + x1) / 2, oy = c.height / 2 + scale * (y0 + y1) / 2;
  return { scale, at: (x, y) => [ox + scale * x, oy - scale * y] };
}

// Top view, the site's frame (x along the jib at slew 0, y across, the slew axis at the origin):
// the no-go zones (enforced: filled red; off: dashed grey), the crane (tower: the jib at the slew
// angle within its reach; gantry: the rail; overhead: the runway and the girder at the bridge's
// position), the trolley, and the load with its swing (2.11): in the trolley's frame, along its axis
// -L cos(theta) sin(phi), across L sin(theta).
function drawTop() {
  const c = $("top"), g = c.getContext("2d"), s = view.last, site = view.site;
  g.clearRect(0, 0, c.width, c.height);
  if (!site) return;
  const zones = zoneStates();
  const xs = [site.trolley.min, site.trolley.max], ys = [0];
  if (site.kind === "tower") { xs.push(-site.trolley.max); ys.push(-site.trolley.max, site.trolley.max); }
  if (site.kind === "overhead") ys.push(site.bridge.min, site.bridge.max);
  if (site.kind === "gantry") ys.push(-(site.trolley.max - site.trolley.min) / 2, (site.trolley.max - site.trolley.min) / 2);
  for (const z of zones) for (const [x, y] of z.polygon) { xs.push(x); ys.push(y); }
  const pad = 0.05 * Math.max(Math.max(...xs) - Math.min(...xs), Math.max(...ys) - Math.min(...ys));
  const { scale, at } = fit(c, Math.min(...xs) - pad, Math.max(...xs) + pad, Math.min(...ys) - pad, Math.max(...ys) + pad);
  g.font = "11px sans-serif";
  for (const z of zones) {
    g.beginPath();
    z.polygon.forEach(([x, y], k) => (k ? g.lineTo(...at(x, y)) : g.moveTo(...at(x, y))));
    g.closePath();
    g.setLineDash(z.enabled ? [] : [5, 4]);
    g.fillStyle = z.enabled ? "rgba(220, 40, 40, 0.35)" : "rgba(150, 150, 150, 0.10)";
    g.strokeStyle = z.enabled ? "#c22" : "#888";
    g.lineWidth = z.enabled ? 2 : 1;
    g.fill(); g.stroke();
    g.setLineDash([]);
    const [lx, ly] = at(Math.min(...z.polygon.map((p) => p[0])), Math.max(...z.polygon.map((p) => p[1])));
    g.fillStyle = z.enabled ? "#a11" : "#777";
    const label = `${z.name}: ${z.enabled ? "enforced" : "off"}, top ${z.top} m`;
    g.fillText(label, Math.max(2, Math.min(lx, c.width - g.measureText(label).width - 2)), Math.max(12, ly - 4));
  }
  view.zonesDrawn = zones.map(({ index, name, enabled, polygon }) => {
    const [cx, cy] = at(polygon.reduce((a, p) => a + p[0], 0) / polygon.length, polygon.reduce((a, p) => a + p[1], 0) / polygon.length);
    return { index, name, enabled, centre_px: [Math.round(cx), Math.round(cy)] };
  });
  g.lineWidth = 1;
  // The crane, then the trolley and the load. pose(a, b): a along the trolley's axis, b across, in the site's frame.
  let pose;
  if (site.kind === "tower") {
    const gam = s ? s.slew_angle : 0;
    pose = (a, b) => at(a * Math.cos(gam) - b * Math.sin(gam), a * Math.sin(gam) + b * Math.cos(gam));
    g.strokeStyle = "#bbb"; g.setLineDash([3, 3]);
    g.beginPath(); g.arc(...at(0, 0), site.trolley.max * scale, 0, 2 * Math.PI); g.stroke(); g.setLineDash([]);
    g.strokeStyle = "#333"; g.lineWidth = 4;
    g.beginPath(); g.moveTo(...pose(-0.15 * site.trolley.max, 0)); g.lineTo(...pose(site.trolley.max, 0)); g.stroke();
    g.fillStyle = "#333"; g.fillRect(at(0, 0)[0] - 4, at(0, 0)[1] - 4, 8, 8);
  } else if (site.kind === "overhead") {
    const yb = s ? s.bridge_position : site.bridge.min;
    pose = (a, b) => at(a, yb + b);
    g.strokeStyle = "#999"; g.lineWidth = 2;
    for (const x of [site.trolley.min, site.trolley.max]) { g.beginPath(); g.moveTo(...at(x, site.bridge.min)); g.lineTo(...at(x, site.bridge.max)); g.stroke(); }
    g.strokeStyle = "#333"; g.lineWidth = 4;
    g.beginPath(); g.moveTo(...at(site.trolley.min, yb)); g.lineTo(...at(site.trolley.max, yb)); g.stroke();
  } else {
    pose = (a, b) => at(a, b);
    g.strokeStyle = "#333"; g.lineWidth = 4;
    g.beginPath(); g.moveTo(...at(site.trolley.min, 0)); g.lineTo(...at(site.trolley.max, 0)); g.stroke();
  }
  g.lineWidth = 1;
  if (!s) return;
  const x = s.trolley_position, L = s.cable_length;
  const [tx, ty] = pose(x, 0);
  const [px, py] = pose(x - L * Math.cos(s.swing_out_of_plane) * Math.sin(s.swing_in_plane), L * Math.sin(s.swing_out_of_plane));
  g.fillStyle = "#36c"; g.fillRect(tx - 6, ty - 6, 12, 12);
  g.strokeStyle = "#36c"; g.beginPath(); g.moveTo(tx, ty); g.lineTo(px, py); g.stroke();
  g.fillStyle = "#c33"; g.beginPath(); g.arc(px, py, 7, 0, 2 * Math.PI); g.fill();
}

// Side view along the trolley's axis: the ground, the jib (or girder) at the site's jib height,
// the trolley, the cable and the load at height jib_height - L cos(theta) cos(phi).
function drawSide() {
  const c = $("side"), g = c.getContext("2d"), s = view.last, site = view.site;
  g.clearRect(0, 0, c.width, c.height);
  if (!site) return;
  const h = site.jib_height, x0 = site.kind === "tower" ? -0.15 * site.trolley.max : site.trolley.min;
  const { at } = fit(c, x0, site.trolley.max, 0, h * 1.05);
  g.strokeStyle = "#8a6"; g.lineWidth = 2; g.beginPath(); g.moveTo(...at(x0, 0)); g.lineTo(...at(site.trolley.max, 0)); g.stroke();
  g.strokeStyle = "#333"; g.lineWidth = 4;
  g.beginPath(); g.moveTo(...at(x0, h)); g.lineTo(...at(site.trolley.max, h)); g.stroke();
  if (site.kind === "tower") { g.beginPath(); g.moveTo(...at(0, 0)); g.lineTo(...at(0, h)); g.stroke(); }
  g.lineWidth = 1;
  if (!s) return;
  const x = s.trolley_position, L = s.cable_length;
  const [tx, ty] = at(x, h);
  const [px, pz] = at(x - L * Math.cos(s.swing_out_of_plane) * Math.sin(s.swing_in_plane),
                      h - L * Math.cos(s.swing_out_of_plane) * Math.cos(s.swing_in_plane));
  g.fillStyle = "#36c"; g.fillRect(tx - 6, ty - 6, 12, 12);
  g.strokeStyle = "#36c"; g.beginPath(); g.moveTo(tx, ty); g.lineTo(px, pz); g.stroke();
  g.fillStyle = "#c33"; g.beginPath(); g.arc(px, pz, 8, 0, 2 * Math.PI); g.fill();
}

function plot(id, series) {
  const c = $(id), g = c.getContext("2d");
  g.clearRect(0, 0, c.width, c.height);
  if (history.length < 2) return;
  let lo = Infinity, hi = -Infinity;
  for (const h of history) for (const s of series) { lo = Math.min(lo, h[s.key]); hi = Math.max(hi, h[s.key]); }
  if (hi - lo < 1e-6) { hi += 0.5; lo -= 0.5; }
  const t0 = history[0].t, t1 = history[history.length - 1].t;
  const X = (t) => 30 + (c.width - 35) * (t - t0) / Math.max(t1 - t0, 1e-6), Y = (v) => c.height - 15 - (c.height - 25) * (v - lo) / (hi - lo);
  g.fillStyle = "#666"; g.font = "10px sans-serif"; g.fillText(hi.toFixed(2), 0, 12); g.fillText(lo.toFixed(2), 0, c.height - 15);
  g.fillText(`last ${(t1 - t0).toFixed(0)} s`, c.width - 60, c.height - 2);
  for (const s of series) {
    g.strokeStyle = s.color; g.beginPath();
    history.forEach((h, k) => (k ? g.lineTo(X(h.t), Y(h[s.key])) : g.moveTo(X(h.t), Y(h[s.key]))));
    g.stroke();
  }
}

// One frame: the status line, the sample panel, the views and the plots from the samples so far.
function draw() {
  const s = view.last;
  $("mode").textContent = view.mode || "waiting";
  $("mode").className = view.mode === "ready" || view.mode === "operating" ? "ok" : view.mode ? "bad" : "";
  $("operation").textContent = view.operation || "-";
  const enforced = zoneStates().filter((z) => z.enabled).map((z) => `${z.index} (${z.name})`);
  $("zones").textContent = view.site ? (enforced.length ? enforced.join(", ") : "none") : "-";
  $("faults").textContent = view.faults.length ? view.faults.join(", ") : "none";
  $("warnings").textContent = view.warnings && view.warnings.length ? view.warnings.join(", ") : "none";
  if (s) {
    $("values").textContent = `cycle       ${s.header.seq}\ntrolley     ${s.trolley_position.toFixed(4)} m\n` +
      `slew        ${(s.slew_angle * 180 / Math.PI).toFixed(2)} deg\ncable       ${s.cable_length.toFixed(3)} m\n` +
      `swing in    ${(s.swing_in_plane * 180 / Math.PI).toFixed(3)} deg\nswing out   ${(s.swing_out_of_plane * 180 / Math.PI).toFixed(3)} deg\n` +
      `V trolley   ${s.applied_trolley_voltage.toFixed(3)} V\nV slew      ${s.applied_slew_voltage.toFixed(3)} V\n` +
      `brakes      ${s.brakes_engaged ? "engaged" : "released"}\nsamples     ${view.sensors}`;
  }
  $("controls").className = mayPublish ? "panel" : "panel readonly";
  $("operator").textContent = mayPublish ? `operator ${view.operator}` : "read-only (log in to command the crane)";
  const m = view.moveStatus;
  $("move_status").textContent = m ? `move ${m.request_id}: ${m.result}${m.reason !== "none" ? " (" + m.reason +
    (m.result === "rejected" ? `: ${m.value} not in [${m.bound_min}, ${m.bound_max}]` : "") + ")" : ""}` +
    (m.result === "moving" ? `, trolley ${m.trolley_to_go.toFixed(3)} m to go` : "") : "";
  drawTop(); drawSide();
  plot("plot_positions", [{ key: "x", color: "#36c" }, { key: "gamma", color: "#c63" }]);
  plot("plot_swing", [{ key: "phi", color: "#36c" }, { key: "theta", color: "#c63" }]);
  plot("plot_voltages", [{ key: "ux", color: "#36c" }, { key: "ugamma", color: "#c63" }]);
}
view.draw = draw; // a test draws a frame synchronously (page_check.js)

function render() {
  draw();
  requestAnimationFrame(render);
}

wireControls();
loadSite();
connect();
requestAnimationFrame(render);
