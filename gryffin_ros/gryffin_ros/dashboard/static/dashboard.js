// The campaign dashboard: polls /api/campaign, redraws when the store has changed. Read-only.
"use strict";

const POLL_MS = 2000;
const state = { data: null, version: null, sortKey: "seq", sortUp: true, pairKey: null };

const $ = (id) => document.getElementById(id);
const label = (item) => (item.units ? `${item.name} (${item.units})` : item.name);
const fmt = (v) => (v === null || v === undefined ? "" : typeof v === "number" ? Number(v.toPrecision(6)).toString() : String(v));

async function refresh() {
  try {
    const response = await fetch("api/campaign", { cache: "no-store" });
    if (!response.ok) throw new Error(`HTTP ${response.status}`);
    const data = await response.json();
    const version = JSON.stringify(data.version);
    if (version !== state.version) {
      state.data = data;
      state.version = version;
      render();
    }
    $("live").textContent = `live · updated ${new Date().toLocaleTimeString()}`;
    $("live").className = "live";
  } catch (error) {
    $("live").textContent = `store unreachable (${error.message}); retrying`;
    $("live").className = "live stale";
  }
}

function render() {
  const d = state.data;
  document.title = `${d.campaign} · gryffin_ros`;
  $("title").textContent = `campaign '${d.campaign}'`;
  const failed = d.experiments.filter((e) => e.failed).length;
  $("summary").textContent = `${d.experiments.length} experiments · ${failed} failed · ${d.pending.length} pending · ` +
    `${d.rejected.length} rejected`;
  $("best-conditions").textContent = bestConditions(d);
  $("hierarchy").textContent = d.hierarchy ? `Best = ${d.hierarchy} (Chimera: a best value of a lower objective can ` +
    "get worse when an experiment first meets a tolerance above it)." : "";
  fillSelect($("objective"), d.objectives.map((o) => o.name));
  fillSelect($("xaxis"), d.axes, 0);
  fillSelect($("yaxis"), d.axes, 1);
  drawBest(d);
  drawParams(d);
  drawPair(d).catch(() => { state.pairKey = null; });
  drawTables(d);
}

function bestConditions(d) {
  const b = d.best_experiment;
  if (!b) return "Best conditions so far: none yet (no successful experiment)";
  const unit = (items, name) => {
    const item = items.find((i) => i.name === name);
    return item && item.units ? ` ${item.units}` : "";
  };
  const params = Object.entries(b.params).map(([k, v]) => `${k} = ${fmt(v)}${unit(d.parameters, k)}`).join(", ");
  const results = Object.entries(b.objectives).map(([k, v]) => `${k} ${fmt(v)}${unit(d.objectives, k)}`).join(", ");
  return `Best conditions so far (experiment ${b.seq}): ${params} → ${results}`;
}

function fillSelect(select, names, preferred = 0) {
  const current = select.value;
  if (select.options.length === names.length) return;
  select.innerHTML = names.map((n) => `<option>${escape(n)}</option>`).join("");
  select.value = names.includes(current) ? current : names[Math.min(preferred, names.length - 1)] || "";
}

function plotDiv(parent, key, cls = "plot") {
  let div = document.getElementById(key);
  if (!div) {
    div = document.createElement("div");
    div.id = key;
    div.className = cls;
    parent.appendChild(div);
  }
  return div;
}

const PLOT_CONFIG = { responsive: true, displaylogo: false };
const LAYOUT = { margin: { l: 60, r: 10, t: 30, b: 45 }, font: { size: 11 }, showlegend: true,
  legend: { orientation: "h", y: -0.25 } };

function drawBest(d) {
  const seq = d.experiments.map((e) => e.seq);
  for (const o of d.objectives) {
    const traces = [
      { x: seq, y: d.experiments.map((e) => e.objectives[o.name]), mode: "markers", name: "experiment",
        marker: { color: "#888", size: 6 }, text: d.experiments.map(hoverText), hoverinfo: "text" },
      { x: seq, y: d.best[o.name], mode: "lines", line: { shape: "hv", color: "#1f77b4", width: 2 },
        name: "best so far" },
    ];
    const failedSeq = d.experiments.filter((e) => e.failed).map((e) => e.seq);
    if (failedSeq.length) {
      traces.push({ x: failedSeq, y: failedSeq.map(() => 0), yaxis: "y2", mode: "markers", name: "failed",
        marker: { symbol: "x", color: "#c33", size: 8 } });
    }
    const shapes = [];
    const tol = d.tolerances[o.name];
    if (tol !== null && tol !== undefined) {
      shapes.push({ type: "line", xref: "paper", x0: 0, x1: 1, y0: tol, y1: tol,
        line: { color: "#e80", dash: "dash", width: 1.5 } });
      traces.push({ x: [null], y: [null], mode: "lines", name: `tolerance ${o.goal === "max" ? "≥" : "≤"} ${fmt(tol)}`,
        line: { color: "#e80", dash: "dash" } });
    }
    Plotly.react(plotDiv($("best"), `best-${o.name}`), traces, { ...LAYOUT, shapes,
      xaxis: { title: { text: "experiment" } }, yaxis: { title: { text: `${label(o)}, goal: ${o.goal}` } },
      yaxis2: { overlaying: "y", range: [0, 1], visible: false } }, PLOT_CONFIG);
  }
}

function drawParams(d) {
  const objective = d.objectives.find((o) => o.name === $("objective").value) || d.objectives[0];
  const ok = d.experiments.filter((e) => !e.failed);
  for (const p of d.parameters) {
    const traces = [{ x: ok.map((e) => e.params[p.name]), y: ok.map((e) => e.objectives[objective.name]),
      mode: "markers", marker: { size: 6, color: ok.map((e) => e.seq), colorscale: "Viridis" }, name: "experiment",
      text: ok.map(hoverText), hoverinfo: "text" }];
    Plotly.react(plotDiv($("params"), `param-${p.name}`, "plot small"), traces, { ...LAYOUT, showlegend: false,
      xaxis: { title: { text: label(p) }, type: p.kind === "categorical" ? "category" : "linear" },
      yaxis: { title: { text: label(objective) } } }, PLOT_CONFIG);
  }
}

async function drawPair(d) {
  const x = $("xaxis").value, y = $("yaxis").value;
  const div = $("pair");
  if (d.constraint_error) {
    $("pair-note").textContent = `The feasible region cannot be drawn: ${d.constraint_error}`;
  }
  if (!x || !y || x === y) { Plotly.purge(div); return; }
  const key = `${x}|${y}`;
  if (state.pairKey !== key) {
    state.pairKey = key;
    state.region = null;
    if (!d.constraint_error) {
      let region = null;
      try {
        const response = await fetch(`api/feasible?x=${encodeURIComponent(x)}&y=${encodeURIComponent(y)}`);
        region = response.ok ? await response.json() : null;
      } catch (error) {
        region = null;
      }
      if (state.pairKey !== key) return;  // the axes changed meanwhile: that drawing is done by the newer call
      if (region === null) state.pairKey = null;  // not drawn: asked again on the next refresh
      state.region = region;
    }
  }
  const px = d.parameters.find((p) => p.name === x), py = d.parameters.find((p) => p.name === y);
  const traces = [];
  if (state.region) {
    traces.push({ type: "heatmap", x: state.region.x.values, y: state.region.y.values, z: state.region.share,
      zmin: 0, zmax: 1, colorscale: [[0, "#ffffff"], [1, "#a8d8a0"]], name: "feasible share",
      showscale: true, colorbar: { title: { text: "feasible share" }, thickness: 12, len: 0.8 },
      hovertemplate: "feasible share %{z}<extra></extra>" });
  }
  const ok = d.experiments.filter((e) => !e.failed), bad = d.experiments.filter((e) => e.failed);
  traces.push({ x: ok.map((e) => e.params[x]), y: ok.map((e) => e.params[y]), mode: "markers", name: "experiment",
    marker: { color: "#1f77b4", size: 7 }, text: ok.map(hoverText), hoverinfo: "text" });
  if (bad.length) traces.push({ x: bad.map((e) => e.params[x]), y: bad.map((e) => e.params[y]), mode: "markers",
    name: "failed", marker: { symbol: "x", color: "#c33", size: 9 } });
  if (d.pending.length) traces.push({ x: d.pending.map((p) => p.params[x]), y: d.pending.map((p) => p.params[y]),
    mode: "markers", name: "pending", marker: { symbol: "circle-open", color: "#e80", size: 11, line: { width: 2 } } });
  Plotly.react(div, traces, { ...LAYOUT, xaxis: { title: { text: label(px) } }, yaxis: { title: { text: label(py) } } },
    PLOT_CONFIG);
}

function hoverText(e) {
  const params = Object.entries(e.params).map(([k, v]) => `${k} ${fmt(v)}`).join("<br>");
  return `#${e.seq} ${e.failed ? "(failed)" : ""}<br>${params}<br>${e.surrogate || ""} s=${fmt(e.strategy)}`;
}

function escape(text) {
  return String(text).replace(/[&<>"]/g, (c) => ({ "&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;" }[c]));
}

function drawing(parameter, option) {
  // the server draws the config's molecules (RDKit); without RDKit the image is hidden and the SMILES column stays
  const src = `api/molecule.svg?parameter=${encodeURIComponent(parameter)}&option=${encodeURIComponent(option)}`;
  return `<img src="${escape(src)}" alt="${escape(option)}" onerror="this.remove()">`;
}

function table(element, columns, rows, sortable) {
  const head = columns.map((c) => `<th class="${c.text ? "text" : ""}" data-key="${escape(c.key)}">${escape(c.title)}` +
    `${sortable && state.sortKey === c.key ? (state.sortUp ? " ▲" : " ▼") : ""}</th>`).join("");
  const body = rows.map((r) => `<tr class="${r.failed ? "failed" : ""}">` + columns.map((c) => c.drawing
    ? `<td class="molecule">${drawing(c.drawing, c.get(r))}</td>`
    : `<td class="${c.text ? "text" : ""}">${escape(fmt(c.get(r)))}</td>`).join("") + "</tr>").join("");
  element.innerHTML = `<thead><tr>${head}</tr></thead><tbody>${body}</tbody>`;
  if (sortable) {
    for (const th of element.querySelectorAll("th")) {
      th.onclick = () => {
        state.sortUp = state.sortKey === th.dataset.key ? !state.sortUp : true;
        state.sortKey = th.dataset.key;
        drawTables(state.data);
      };
    }
  }
}

function drawTables(d) {
  const columns = [{ key: "seq", title: "#", get: (e) => e.seq },
    { key: "experiment_id", title: "experiment", text: true, get: (e) => e.experiment_id.slice(0, 8) },
    ...d.parameters.flatMap((p) => [{ key: `p:${p.name}`, title: label(p), text: p.kind === "categorical",
      get: (e) => e.params[p.name] }, ...(p.smiles ? [{ key: `s:${p.name}`, title: `${p.name} SMILES`, text: true,
      get: (e) => p.smiles[e.params[p.name]] }] : [])]),
    ...d.objectives.map((o) => ({ key: `o:${o.name}`, title: label(o), get: (e) => e.objectives[o.name] })),
    { key: "failed", title: "failed", text: true, get: (e) => (e.failed ? "yes" : "") },
    { key: "strategy", title: "strategy", get: (e) => e.strategy },
    { key: "surrogate", title: "surrogate", text: true, get: (e) => e.surrogate }];
  const column = columns.find((c) => c.key === state.sortKey) || columns[0];
  const rows = [...d.experiments].sort((a, b) => {
    const va = column.get(a), vb = column.get(b);
    const order = va === vb ? 0 : va === null || va === undefined ? 1 : vb === null || vb === undefined ? -1 : va < vb ? -1 : 1;
    return state.sortUp ? order : -order;
  });
  table($("experiments"), columns, rows, true);
  const drawings = d.parameters.filter((p) => p.smiles).map((p) => ({ key: `m:${p.name}`, title: p.name,
    drawing: p.name, get: (e) => e.params[p.name] }));
  table($("pending"), columns.filter((c) => c.key === "experiment_id" || c.key.startsWith("p:") ||
    c.key.startsWith("s:") || c.key === "strategy" || c.key === "surrogate").concat(drawings), d.pending, false);
  table($("rejected"), [{ key: "id", title: "experiment", text: true, get: (r) => (r.experiment_id || "").slice(0, 8) },
    { key: "reason", title: "reason", text: true, get: (r) => r.reason }], d.rejected, false);
  $("n-pending").textContent = `(${d.pending.length})`;
  $("n-rejected").textContent = `(${d.rejected.length})`;
}

$("objective").onchange = () => state.data && drawParams(state.data);
$("xaxis").onchange = $("yaxis").onchange = () => state.data && drawPair(state.data).catch(() => { state.pairKey = null; });
refresh();
setInterval(refresh, POLL_MS);
