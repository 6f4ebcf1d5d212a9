// DOM wiring: routes (#/, #/upload, #/take/ID?run=RID, #/compare), events, polling.
import * as api from "./api.js";
import * as charts from "./charts.js";

const main = document.getElementById("main");
const OVERVIEW_FRAMES = 800; // frames of a take drawn before any window is loaded
const REVIEW = { unreviewed: "unreviewed", approved: "approved", needs_fix: "needs fix", rejected: "rejected" };
let teardown = () => {};

const h = (tag, attrs = {}, ...children) => {
  const el = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (k.startsWith("on")) el.addEventListener(k.slice(2), v);
    else if (v === true) el.setAttribute(k, "");
    else if (v !== false && v != null) el.setAttribute(k, v);
  }
  for (const c of children.flat()) if (c != null) el.append(c instanceof Node ? c : String(c));
  return el;
};
const badge = (text, cls) => h("span", { class: `badge ${cls || text}` }, text);
const fmt = (v, digits = 1) => (v == null || Number.isNaN(v) ? "–" : Number(v).toFixed(digits));
const plotlyReady = () => new Promise((resolve) => {
  const check = () => (window.Plotly ? resolve(window.Plotly) : setTimeout(check, 20));
  check();
});

function route() {
  teardown();
  teardown = () => {};
  delete main.dataset.ready;
  const [path, query] = location.hash.replace(/^#/, "").split("?");
  const params = new URLSearchParams(query || "");
  const parts = (path || "/").split("/").filter(Boolean);
  const view = parts[0] === "take" ? takeView(parts[1], params.get("run"))
    : parts[0] === "upload" ? uploadView()
    : parts[0] === "compare" ? compareView(params)
    : listView(params);
  view.catch((e) => main.replaceChildren(h("p", { class: "error" }, e.message)));
}
window.addEventListener("hashchange", route);
route();

// ---------------------------------------------------------------- upload
function dropZone(onFile) {
  const input = h("input", { type: "file", id: "file-input", style: "display:none" });
  const zone = h("div", { class: "dropzone", id: "dropzone" },
    h("p", {}, "Drop a take here (BVH, TRC, CSV, OpenPose, MediaPipe, NPY/NPZ, JSON) or ",
      h("button", { onclick: () => input.click() }, "choose a file")), input);
  input.addEventListener("change", () => input.files[0] && onFile(input.files[0]));
  zone.addEventListener("dragover", (e) => { e.preventDefault(); zone.classList.add("over"); });
  zone.addEventListener("dragleave", () => zone.classList.remove("over"));
  zone.addEventListener("drop", (e) => {
    e.preventDefault(); zone.classList.remove("over");
    if (e.dataTransfer.files[0]) onFile(e.dataTransfer.files[0]);
  });
  return zone;
}

function uploader(status) {
  return async (file) => {
    const bar = h("progress", { max: 100, value: 0, id: "upload-progress" });
    const text = h("span", { id: "upload-status" }, `uploading ${file.name}…`);
    status.replaceChildren(bar, " ", text);
    try {
      const created = await api.uploadTake(file, (f) => { bar.value = Math.round(f * 50); });
      const run = await api.waitForRun(created.run_id, (r) => {
        bar.value = 50 + r.progress / 2;
        text.textContent = `analysing: ${r.step} (${r.progress} %)`;
      });
      if (run.status === "failed") throw new Error(`analysis failed: ${run.error}`);
      text.replaceChildren("done — ", h("a", { href: api.takeLink(created.id, created.run_id), id: "open-take" }, `open ${created.name}`));
    } catch (e) {
      status.replaceChildren(h("p", { class: "error", id: "upload-error" }, `Rejected: ${e.message}`));
    }
  };
}

async function uploadView() {
  const status = h("div", { id: "upload-area" });
  main.replaceChildren(h("h1", {}, "Upload a take"), dropZone(uploader(status)), status,
    h("p", { class: "muted" }, "The analysis (twist refinement, joint limits, filtering) starts with default options."));
}

// ---------------------------------------------------------------- list
async function listView(params) {
  const status = params.get("status") || "";
  const review = params.get("review") || "";
  const page = await api.listTakes({ status, review_status: review, limit: 200 });
  const select = (name, value, options) => h("select", { id: `filter-${name}`, onchange: (e) => {
    const next = new URLSearchParams(params); next.set(name, e.target.value); location.hash = `#/?${next}`; } },
    options.map(([v, label]) => h("option", { value: v, selected: v === value }, label)));
  const uploadStatus = h("div", { id: "upload-area" });
  const rows = page.items.map((t) => h("tr", { class: "clickable", "data-take": t.id, onclick: () => { location.hash = api.takeLink(t.id); } },
    h("td", {}, h("img", { class: "thumb", src: api.thumbnailUrl(t.id, t.latest_run_id), alt: "" })),
    h("td", {}, t.name), h("td", {}, t.format), h("td", {}, `${t.n_frames} @ ${fmt(t.fps, 0)} fps`),
    h("td", {}, t.n_joints), h("td", {}, badge(t.status || "none")), h("td", {}, badge(REVIEW[t.review_status], t.review_status)),
    h("td", {}, t.n_findings ?? "–"),
    h("td", {}, h("button", { onclick: async (e) => {
      e.stopPropagation();
      if (confirm(`Delete ${t.name}?`)) { await api.deleteTake(t.id); route(); }
    } }, "delete"))));
  main.replaceChildren(
    h("h1", {}, `Takes (${page.total})`),
    dropZone(async (file) => { await uploader(uploadStatus)(file); }), uploadStatus,
    h("div", { class: "controls" }, "Run status ", select("status", status, [["", "any"], ["queued", "queued"], ["running", "running"], ["done", "done"], ["failed", "failed"]]),
      "Review ", select("review", review, [["", "any"], ...Object.entries(REVIEW)])),
    h("table", { id: "take-list" }, h("thead", {}, h("tr", {}, ["", "name", "format", "frames", "joints/points", "run", "review", "findings", ""].map((c) => h("th", {}, c)))),
      h("tbody", {}, rows)),
  );
}

// ---------------------------------------------------------------- take view
async function takeView(takeId, runParam) {
  const take = await api.getTake(takeId);
  const runs = take.runs;
  const run = runs.find((r) => r.id === runParam) || runs[runs.length - 1];
  const header = h("div", {}, h("h1", {}, take.name, " ", badge(run ? run.status : "none")),
    h("p", { class: "muted" }, `${take.format.toUpperCase()} · ${take.n_frames} frames at ${fmt(take.fps, 2)} fps · ${take.n_joints} ${take.kind === "motion" ? "joints" : "keypoints"} · sha256 ${take.sha256.slice(0, 12)}…`));
  main.replaceChildren(header);
  if (!run) return;
  if (run.status !== "done") {
    const bar = h("progress", { max: 100, value: run.progress }), text = h("span", {}, run.step);
    main.append(h("p", {}, bar, " ", text));
    const final = await api.waitForRun(run.id, (r) => { bar.value = r.progress; text.textContent = `${r.step} (${r.progress} %)`; });
    if (final.status === "failed") { main.append(h("p", { class: "error" }, final.error)); return; }
    route(); return;
  }
  const [result, filters, overview] = await Promise.all([
    api.getResult(run.id), api.listFilters(), api.getFrames(run.id, { maxFrames: OVERVIEW_FRAMES })]);
  const fps = result.summary.fps;
  const state = { frame: 0, playing: false, speed: 1, camera: null };
  let detail = null;

  // Layout
  const frameLabel = h("span", { id: "frame-label" });
  const scrubber = h("input", { type: "range", id: "scrubber", min: 0, max: result.summary.n_frames - 1, value: 0, step: 1 });
  const playButton = h("button", { id: "play", class: "primary" }, "▶ play");
  const speed = h("select", { id: "speed" }, [0.25, 0.5, 1, 2].map((s) => h("option", { value: s, selected: s === 1 }, `${s}×`)));
  const rawDiv = h("div", { id: "view-raw", class: "view3d" });
  const corrDiv = h("div", { id: "view-corrected", class: "view3d" });
  main.append(
    runPicker(take, run),
    h("div", { class: "row" }, h("div", { class: "col panel" }, rawDiv), h("div", { class: "col panel" }, corrDiv)),
    h("div", { class: "controls panel" }, playButton, "speed ", speed, scrubber, frameLabel),
  );
  const timelines = h("div", {});
  main.append(timelines, findingsTable(result.findings, fps, (f) => jump(f)),
    h("div", { class: "row" }, h("div", { class: "col" }, reviewPanel(take)), h("div", { class: "col" }, downloadsPanel(run, result), stepsPanel(result), rerunPanel(take, run, filters))));

  const Plotly = await plotlyReady();
  const names = result.points.names, parents = result.points.parents;
  const index = new Map(names.map((n, i) => [n, i]));
  const extent = charts.bodyExtent([overview.raw]);
  const flaggedAt = (frame) => new Set(result.findings.filter((f) => f.start_frame <= frame && frame <= f.end_frame)
    .map((f) => index.get(f.joint)).filter((i) => i !== undefined));
  const nearest = (frames, f) => {
    let lo = 0, hi = frames.length - 1;
    while (lo < hi) { const mid = (lo + hi) >> 1; if (frames[mid] < f) lo = mid + 1; else hi = mid; }
    return lo > 0 && Math.abs(frames[lo - 1] - f) <= Math.abs(frames[lo] - f) ? lo - 1 : lo;
  };
  const pointsAt = (f) => {
    const source = detail && f >= detail.frames[0] && f <= detail.frames[detail.frames.length - 1] ? detail : overview;
    const k = nearest(source.frames, f);
    return { raw: source.raw[k], corrected: source.corrected[k], shown: source.frames[k] };
  };
  const charts2d = [];
  const draw = () => {
    const f = state.frame, p = pointsAt(f), flagged = flaggedAt(f);
    const title = (what) => `${what} — frame ${p.shown}`;
    const bounds = charts.sceneBounds(p.raw, extent);
    const raw = charts.skeletonFigure(p.raw, parents, flagged, bounds, title("raw"), state.camera);
    const corr = charts.skeletonFigure(p.corrected, parents, new Set(), bounds, title("corrected"), state.camera);
    Plotly.react(rawDiv, raw.data, raw.layout, { displaylogo: false });
    Plotly.react(corrDiv, corr.data, corr.layout, { displaylogo: false });
    frameLabel.textContent = `frame ${f} / ${result.summary.n_frames - 1} · ${fmt(f / fps, 3)} s · ${flagged.size} flagged joint(s)`;
    scrubber.value = f;
    // The time cursor on the 2D charts follows at most every 150 ms: relayouts cost more than
    // the two 3D redraws together.
    const now = performance.now();
    if (!state.playing || now - lastCursor > 150) {
      lastCursor = now;
      for (const div of charts2d) Plotly.relayout(div, charts.cursorLayout(f / fps));
    }
  };
  let lastCursor = 0;
  const loadDetail = async () => {
    const f = state.frame;
    detail = await api.getFrames(run.id, { start: Math.max(0, f - 200), stop: f + 200, maxFrames: 401 });
    if (!state.playing) draw();
  };
  const jump = (f) => { state.frame = Math.max(0, Math.min(result.summary.n_frames - 1, Math.round(f))); draw(); loadDetail(); };

  await Plotly.newPlot(rawDiv, [], {});
  await Plotly.newPlot(corrDiv, [], {});
  draw();
  // Same camera: whichever view is rotated drives both.
  for (const [src, dst] of [[rawDiv, corrDiv], [corrDiv, rawDiv]]) {
    src.on("plotly_relayout", (e) => {
      if (e["scene.camera"]) { state.camera = e["scene.camera"]; Plotly.relayout(dst, { "scene.camera": state.camera }); }
    });
  }
  scrubber.addEventListener("input", () => { state.frame = Number(scrubber.value); draw(); });
  scrubber.addEventListener("change", loadDetail);
  speed.addEventListener("change", () => { state.speed = Number(speed.value); });
  let last = 0, handle = 0;
  const tick = (now) => {
    if (!state.playing) return;
    const advance = Math.floor(((now - last) / 1000) * fps * state.speed);
    if (advance >= 1) { state.frame = (state.frame + advance) % result.summary.n_frames; last = now; draw(); }
    handle = requestAnimationFrame(tick);
  };
  playButton.addEventListener("click", () => {
    state.playing = !state.playing;
    playButton.textContent = state.playing ? "❚❚ pause" : "▶ play";
    if (state.playing) { detail = null; last = performance.now(); handle = requestAnimationFrame(tick); } else loadDetail();
  });
  teardown = () => { state.playing = false; cancelAnimationFrame(handle); };

  // Timelines on a shared time axis (seconds).
  const addChart = async (id, heading, figure, onClickFrame) => {
    const div = h("div", { id, class: "chart" });
    timelines.append(h("div", { class: "panel" }, h("h2", {}, heading), div));
    await Plotly.newPlot(div, figure.data, figure.layout, { displaylogo: false, responsive: true });
    div.on("plotly_click", (e) => {
      const bar = e.points.find((p) => p.customdata !== undefined);
      const f = onClickFrame(bar || e.points[0]);
      if (f != null) jump(f);
    });
    div.on("plotly_relayout", (e) => {
      if (e["xaxis.range[0]"] === undefined) return;
      for (const other of charts2d) if (other !== div) Plotly.relayout(other, { "xaxis.range": [e["xaxis.range[0]"], e["xaxis.range[1]"]] });
    });
    charts2d.push(div);
  };
  const series = result.series;
  if (series.twist) {
    await addChart("chart-twist", `Twist θP and removed offset (${series.twist.intervals.length} flagged interval(s))`,
      charts.twistFigure(series.twist, fps, 0), (p) => {
        if (p.customdata) return p.customdata[0];
        const f = p.x * fps;
        const inside = series.twist.intervals.find((i) => i.start_frame <= f && f <= i.end_frame + 1);
        return inside ? inside.start_frame : f;
      });
  }
  if (series.limits) {
    await addChart("chart-limits", "Joint-limit violations (joint × time, degrees outside the limits)",
      charts.limitsFigure(series.limits, fps, 0), (p) => p.x * fps);
  } else if (result.steps.limits && result.steps.limits.state !== "skipped") {
    timelines.append(h("p", { class: "muted", id: "limits-note" }, `Joint limits: ${result.steps.limits.message}`));
  }
  if (result.kind === "keypoints") {
    const pick = h("select", { id: "keypoint-pick" }, names.map((n, i) => h("option", { value: i }, n)));
    timelines.append(h("div", { class: "controls" }, "keypoint ", pick));
    const k = () => Number(pick.value);
    const trajectory = () => charts.trajectoryFigure(overview.frames, fps, overview.raw.map((p) => p[k()]), overview.corrected.map((p) => p[k()]), result.summary.length_unit, state.frame / fps);
    await addChart("chart-trajectory", "Raw vs filtered trajectory", trajectory(), (p) => p.x * fps);
    const weights = series.filter && Object.keys(series.filter.weights).length ? series.filter.weights : null;
    if (weights) await addChart("chart-weights", "Filter weights (stacked: Kalman / One Euro / EMA)", charts.weightsFigure(series.frames, fps, weights, k(), 0), (p) => p.x * fps);
    pick.addEventListener("change", () => {
      const t = trajectory(); Plotly.react("chart-trajectory", t.data, t.layout);
      if (weights) { const w = charts.weightsFigure(series.frames, fps, weights, k(), state.frame / fps); Plotly.react("chart-weights", w.data, w.layout); }
    });
  }
  main.dataset.ready = "1";
}

function runPicker(take, run) {
  const select = h("select", { id: "run-pick", onchange: (e) => { location.hash = api.takeLink(take.id, e.target.value); } },
    take.runs.map((r, i) => h("option", { value: r.id, selected: r.id === run.id },
      `run ${i + 1} · ${r.status} · ${r.options.checks.join("+")}${r.options.filter_method ? ` · ${r.options.filter_method}` : ""}`)));
  return h("div", { class: "controls" }, "Run ", select,
    run.server_time_s != null ? h("span", { class: "muted" }, `server time ${fmt(run.server_time_s, 2)} s`) : null,
    h("a", { href: `#/compare?a=${run.id}` }, "compare…"));
}

function findingsTable(findings, fps, onJump) {
  const columns = [["kind", "kind"], ["joint", "joint"], ["start_frame", "frames"], ["duration", "duration (s)"], ["value", "offset / outside"], ["confidence", "confidence"]];
  const rows = findings.map((f) => ({ ...f, duration: (f.end_frame - f.start_frame + 1) / fps }));
  let key = "start_frame", dir = 1;
  const body = h("tbody");
  const render = () => {
    rows.sort((a, b) => ((a[key] ?? -Infinity) > (b[key] ?? -Infinity) ? dir : (a[key] ?? -Infinity) < (b[key] ?? -Infinity) ? -dir : 0));
    body.replaceChildren(...rows.map((f) => h("tr", { class: "clickable finding", onclick: () => onJump(f.start_frame) },
      h("td", {}, f.kind), h("td", {}, f.joint), h("td", {}, `${f.start_frame}–${f.end_frame}`), h("td", {}, fmt(f.duration, 3)),
      h("td", {}, f.value == null ? "–" : `${fmt(f.value, 1)} ${f.unit === "deg" ? "°" : f.unit}`), h("td", {}, fmt(f.confidence, 2)))));
  };
  const head = h("tr", {}, columns.map(([k, label]) => h("th", { class: "sortable", onclick: () => { dir = key === k ? -dir : 1; key = k; render(); } }, label)));
  render();
  return h("div", { class: "panel" }, h("h2", {}, `Findings (${findings.length})`),
    findings.length ? h("table", { id: "findings" }, h("thead", {}, head), body) : h("p", { class: "muted" }, "No findings."));
}

function reviewPanel(take) {
  const current = take.reviews[0];
  const status = h("select", { id: "review-status" }, Object.entries(REVIEW).map(([v, l]) => h("option", { value: v, selected: v === (current ? current.status : "unreviewed") }, l)));
  const notes = h("textarea", { id: "review-notes", placeholder: "notes" });
  const reviewer = h("input", { id: "reviewer", value: localStorage.getItem("mocapqa-reviewer") || "", placeholder: "your name" });
  const message = h("span", { id: "review-message", class: "muted" });
  const save = h("button", { id: "review-save", class: "primary", onclick: async () => {
    try {
      localStorage.setItem("mocapqa-reviewer", reviewer.value);
      await api.addReview(take.id, { status: status.value, notes: notes.value, reviewer: reviewer.value || "anonymous" });
      message.textContent = "saved";
      route();
    } catch (e) { message.textContent = e.message; message.className = "error"; }
  } }, "save review");
  const history = take.reviews.map((r) => h("li", {}, `${new Date(r.created_at).toLocaleString()} · ${r.reviewer}: `, badge(REVIEW[r.status], r.status), r.notes ? ` — ${r.notes}` : ""));
  return h("div", { class: "panel", id: "review-panel" }, h("h2", {}, "Review"), h("div", { class: "controls" }, status, reviewer, save, message), notes,
    h("ul", { id: "review-history" }, history));
}

function downloadsPanel(run, result) {
  const labels = { bvh: "corrected BVH", csv: "filtered keypoints (CSV)", trc: "filtered keypoints (TRC)", report: "JSON report", "report.html": "HTML report" };
  const kinds = [...(result.downloads || ["report"]), "report.html"];
  return h("div", { class: "panel" }, h("h2", {}, "Downloads"),
    kinds.map((k) => h("a", { href: api.downloadUrl(run.id, k), download: "", id: `download-${k.replace(".", "-")}`, style: "margin-right:12px" }, labels[k] || k)));
}

function stepsPanel(result) {
  return h("div", { class: "panel" }, h("h2", {}, "Steps"),
    h("ul", { class: "steps" }, Object.entries(result.steps).map(([name, s]) => h("li", {}, h("b", {}, name), " ", badge(s.state, s.state === "done" ? "done" : ""), " ", s.message))));
}

function rerunPanel(take, run, filters) {
  const target = take.kind === "motion" ? "rotations" : "keypoints";
  const usable = filters.filter((f) => f.applies_to.includes(target));
  const checks = ["twist", "limits", "filter"].map((c) => h("label", {}, h("input", { type: "checkbox", value: c, checked: run.options.checks.includes(c) }), ` ${c}`));
  const twist = h("select", { id: "twist-method" }, ["robust", "paper"].map((m) => h("option", { value: m, selected: m === run.options.twist_method }, m)));
  const method = h("select", { id: "filter-method" }, h("option", { value: "" }, take.kind === "motion" ? "no filter" : "adaptive (default)"),
    usable.map((f) => h("option", { value: f.name, selected: f.name === run.options.filter_method }, f.label)));
  const preset = h("select", { id: "filter-preset" });
  const params = h("div", { id: "filter-params" });
  const fillParams = () => {
    const entry = usable.find((f) => f.name === method.value) || (take.kind === "keypoints" ? usable.find((f) => f.name === "adaptive") : null);
    preset.replaceChildren(...(entry ? entry.presets : []).map((p) => h("option", { value: p }, p)));
    params.replaceChildren(...(entry ? entry.parameters : []).map((p) => h("label", {}, `${p.name}${p.unit ? ` (${p.unit})` : ""} `,
      h("input", { "data-param": p.name, "data-type": p.type, placeholder: String(p.default), size: 8 }))));
  };
  method.addEventListener("change", fillParams);
  fillParams();
  const message = h("span", { class: "muted" });
  const start = h("button", { class: "primary", id: "rerun", onclick: async () => {
    const filter_params = {};
    for (const input of params.querySelectorAll("input")) {
      if (input.value === "") continue;
      const type = input.dataset.type;
      filter_params[input.dataset.param] = type === "str" ? input.value : type === "bool" ? input.value === "true" : Number(input.value);
    }
    try {
      const created = await api.startRun(take.id, {
        checks: checks.map((l) => l.firstChild).filter((c) => c.checked).map((c) => c.value),
        twist_method: twist.value, filter_method: method.value || null, filter_preset: preset.value || null, filter_params,
      });
      location.hash = api.takeLink(take.id, created.id);
    } catch (e) { message.textContent = e.message; message.className = "error"; }
  } }, "re-run");
  return h("div", { class: "panel" }, h("h2", {}, "Re-run with other options (earlier runs are kept)"),
    h("div", { class: "controls" }, checks), h("div", { class: "controls" }, "twist ", twist, " filter ", method, " preset ", preset),
    params, h("div", { class: "controls" }, start, message));
}

// ---------------------------------------------------------------- compare
async function compareView(params) {
  const page = await api.listTakes({ limit: 500 });
  const options = [];
  for (const t of page.items) {
    const take = await api.getTake(t.id);
    take.runs.forEach((r, i) => options.push([r.id, `${t.name} · run ${i + 1} (${r.status})`]));
  }
  const pick = (name) => h("select", { id: `compare-${name}`, onchange: (e) => {
    const next = new URLSearchParams(params); next.set(name, e.target.value); location.hash = `#/compare?${next}`; } },
    h("option", { value: "" }, "choose…"), options.map(([v, l]) => h("option", { value: v, selected: v === params.get(name) }, l)));
  main.replaceChildren(h("h1", {}, "Compare two takes or runs"), h("div", { class: "controls" }, "A ", pick("a"), " B ", pick("b")));
  const ids = [params.get("a"), params.get("b")].filter(Boolean);
  const results = await Promise.all(ids.map(async (id) => ({ run: await api.getRun(id), result: await api.getResult(id).catch(() => null) })));
  if (!results.length) return;
  const metric = (label, get) => h("tr", {}, h("td", {}, label), results.map((r) => h("td", {}, r.result ? get(r.result, r.run) : "–")));
  const maxOffset = (res) => {
    const s = res.series.twist && res.series.twist.summaries;
    return s && s.length ? `${fmt(Math.max(...s.map((c) => c.max_abs_offset_deg)), 1)} °` : "–";
  };
  main.append(h("table", { class: "kv", id: "compare-table" },
    h("thead", {}, h("tr", {}, h("th", {}, "metric"), results.map((r) => h("th", {}, options.find(([v]) => v === r.run.id)?.[1] || r.run.id)))),
    h("tbody", {},
      metric("frames", (x) => x.summary.n_frames), metric("frame rate (fps)", (x) => fmt(x.summary.fps, 2)),
      metric("duration (s)", (x) => fmt(x.summary.duration_s, 2)), metric("findings", (x) => x.summary.n_findings),
      metric("twist intervals", (x) => x.summary.findings_by_kind.twist || 0), metric("largest removed offset", maxOffset),
      metric("joint-limit intervals", (x) => (x.steps.limits.state === "done" ? x.summary.findings_by_kind.limits || 0 : x.steps.limits.state)),
      metric("filter", (x) => (x.steps.filter.state === "done" ? x.series.filter?.method || x.options.filter_method : x.steps.filter.state)),
      metric("server time (s)", (x, run) => fmt(run.server_time_s, 3)),
      metric("options", (x) => JSON.stringify(x.options)))));
}
