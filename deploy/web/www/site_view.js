// crane_web's site page (site.html): draws /site/view.json (its fields: site_page.hpp) every
// kPeriodMs. Every figure it shows (outlines, capsules, distances, bands) comes computed from the
// server; this file only maps the site frame (x east, y north, metres) to the canvas and draws.
// window.siteView exposes what was drawn, for tests (tests/web/site_page_check.js).
"use strict";
(function () {
  const kPeriodMs = 250;
  const kColours = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2", "#17becf"];
  const plan = document.getElementById("plan");
  const ctx = plan.getContext("2d");
  const state = { view: null, views: 0, errors: 0, drawn: null, frame: null };
  window.siteView = state;

  // The frame: every crane's reach and counter-jib, and every zone, in view with a margin.
  function frameOf(view) {
    let xmin = Infinity, xmax = -Infinity, ymin = Infinity, ymax = -Infinity;
    const add = (x, y) => { xmin = Math.min(xmin, x); xmax = Math.max(xmax, x); ymin = Math.min(ymin, y); ymax = Math.max(ymax, y); };
    for (const c of view.cranes) {
      const r = Math.max(c.reach, c.counter_jib) + 0.2;
      add(c.base[0] - r, c.base[1] - r);
      add(c.base[0] + r, c.base[1] + r);
    }
    for (const z of view.zones) for (const p of z.polygon) add(p[0], p[1]);
    const size = Math.max(xmax - xmin, ymax - ymin, 1e-3);
    const scale = (Math.min(plan.width, plan.height) - 20) / size;
    const cx = (xmin + xmax) / 2, cy = (ymin + ymax) / 2;
    return {
      scale,
      px: (x, y) => [plan.width / 2 + (x - cx) * scale, plan.height / 2 - (y - cy) * scale],
    };
  }

  function polygon(f, points) {
    ctx.beginPath();
    points.forEach((p, i) => { const [u, v] = f.px(p[0], p[1]); if (i === 0) ctx.moveTo(u, v); else ctx.lineTo(u, v); });
    ctx.closePath();
  }

  function capsule(f, part, colour) {
    const [ax, ay] = f.px(part.a[0], part.a[1]);
    const [bx, by] = f.px(part.b[0], part.b[1]);
    ctx.strokeStyle = colour;
    ctx.lineCap = "round";
    ctx.lineWidth = Math.max(2, 2 * part.radius * f.scale);
    ctx.beginPath();
    ctx.moveTo(ax, ay);
    ctx.lineTo(bx + (ax === bx && ay === by ? 0.01 : 0), by);
    ctx.stroke();
  }

  function draw() {
    const view = state.view;
    ctx.clearRect(0, 0, plan.width, plan.height);
    if (!view) return;
    const f = frameOf(view);
    state.frame = f;
    const drawn = { cranes: [], zones: view.zones.length };
    ctx.fillStyle = "#ddd";
    ctx.strokeStyle = "#999";
    ctx.lineWidth = 1;
    for (const z of view.zones) { polygon(f, z.polygon); ctx.fill(); ctx.stroke(); }
    view.cranes.forEach((c, i) => {
      const colour = kColours[i % kColours.length];
      const [bx, by] = f.px(c.base[0], c.base[1]);
      // Reach (dotted).
      ctx.setLineDash([2, 4]);
      ctx.strokeStyle = colour;
      ctx.lineWidth = 1;
      ctx.beginPath();
      ctx.arc(bx, by, c.reach * f.scale, 0, 2 * Math.PI);
      ctx.stroke();
      // Held (filled) and requested (dashed) airspace.
      ctx.setLineDash([]);
      ctx.fillStyle = colour;
      ctx.strokeStyle = colour;
      for (const box of c.held) {
        polygon(f, box);
        ctx.globalAlpha = 0.25;
        ctx.fill();
        ctx.globalAlpha = 1.0;
        ctx.stroke();
      }
      ctx.setLineDash([6, 4]);
      ctx.lineWidth = 1.5;
      for (const box of c.requested) { polygon(f, box); ctx.stroke(); }
      ctx.setLineDash([]);
      // The structure and the load at the reported pose.
      const entry = { name: c.name, base_px: [bx, by], held: c.held.length, requested: c.requested.length, load_px: null };
      for (const part of c.parts) {
        if (part.part === "jib" || part.part === "counter_jib") {
          ctx.globalAlpha = 0.7;
          capsule(f, part, colour);
          ctx.globalAlpha = 1.0;
        } else if (part.part === "load") {
          const [lx, ly] = f.px(part.a[0], part.a[1]);
          entry.load_px = [lx, ly];
          ctx.fillStyle = colour;
          ctx.beginPath();
          ctx.arc(lx, ly, Math.max(2, part.radius * f.scale), 0, 2 * Math.PI);
          ctx.fill();
        }
      }
      ctx.fillStyle = c.state === "silent" ? "#888" : colour;
      ctx.fillRect(bx - 4, by - 4, 8, 8);
      ctx.font = "12px sans-serif";
      ctx.fillText(c.name + (c.waiting ? " (waits)" : c.holding === "whole_reach" ? " (whole reach)" :
                   c.holding === "out_of_service" ? " (out of service)" : ""), bx + 6, by - 6);
      drawn.cranes.push(entry);
    });
    state.drawn = drawn;
  }

  function fixed(v, digits) { return v === null || v === undefined ? "-" : Number(v).toFixed(digits); }

  function tables(view) {
    document.getElementById("site").textContent = view.site;
    const svc = document.getElementById("service");
    if (view.service && view.service.heard_s_ago < 1.0) {
      svc.textContent = "epoch " + view.service.epoch + ", yields " + view.service.yields +
                        ", unresolved " + view.service.unresolved;
      svc.className = "ok";
    } else {
      svc.textContent = view.service ? "silent for " + fixed(view.service.heard_s_ago, 1) + " s" : "not heard";
      svc.className = "bad";
    }
    document.getElementById("margins").textContent =
        "warning " + view.margins.warning + " m, slow down " + view.margins.slow_down + " m, stop " + view.margins.stop + " m";
    document.getElementById("closest").textContent = view.closest
        ? "closest " + fixed(view.closest.distance, 3) + " m (" + view.closest.parts + " at " + fixed(view.closest.at, 1) + " s)" : "";
    const waits = view.cranes.filter((c) => c.waits_for.length > 0).map((c) =>
        c.name + " waits for " + c.waits_for.join(", ") + " (" + c.wait_reason +
        (c.waited_s !== null ? ", " + fixed(c.waited_s, 0) + " s" : "") + ")");
    document.getElementById("waits").textContent = waits.join("; ");
    const rows = [["", "crane", "state", "holding", "request", "instruction", "slew [deg]", "trolley [m]", "cable [m]",
                   "work left [s]", "heard [s ago]"]];
    view.cranes.forEach((c, i) => {
      rows.push([i, c.name, c.state, c.holding || "-", c.waiting ? "waiting" : "-", c.instruction || "-",
                 c.pose ? fixed(c.pose.slew * 180 / Math.PI, 1) : "-", c.pose ? fixed(c.pose.trolley, 3) : "-",
                 c.pose ? fixed(c.pose.cable_length, 3) : "-", c.work_left_s !== null ? fixed(c.work_left_s, 1) : "-",
                 fixed(c.heard_s_ago, 1)]);
    });
    const table = document.getElementById("cranes");
    table.replaceChildren(...rows.map((r, k) => {
      const tr = document.createElement("tr");
      r.forEach((cell, j) => {
        const td = document.createElement(k === 0 ? "th" : "td");
        if (k > 0 && j === 0) {
          const sw = document.createElement("span");
          sw.className = "swatch";
          sw.style.background = kColours[cell % kColours.length];
          td.appendChild(sw);
        } else {
          td.textContent = cell;
        }
        tr.appendChild(td);
      });
      return tr;
    }));
    const pairs = document.getElementById("pairs");
    const head = document.createElement("tr");
    for (const h of ["cranes", "distance [m]", "between"]) { const th = document.createElement("th"); th.textContent = h; head.appendChild(th); }
    pairs.replaceChildren(head, ...view.pairs.map((p) => {
      const tr = document.createElement("tr");
      tr.className = p.band;
      for (const cell of [p.cranes.join("-"), fixed(p.distance, 3), p.parts.join("-")]) {
        const td = document.createElement("td");
        td.textContent = cell;
        tr.appendChild(td);
      }
      return tr;
    }));
  }

  async function poll() {
    try {
      const response = await fetch("/site/view.json", { cache: "no-store" });
      const view = await response.json();
      if (!response.ok || view.error) throw new Error(view.error || "HTTP " + response.status);
      state.view = view;
      state.views += 1;
      tables(view);
      draw();
    } catch (error) {
      state.errors += 1;
      const svc = document.getElementById("service");
      svc.textContent = "no view: " + error.message;
      svc.className = "bad";
    }
    setTimeout(poll, kPeriodMs);
  }
  state.draw = draw;
  poll();
})();
