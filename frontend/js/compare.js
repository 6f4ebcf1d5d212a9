// Compare two runs: counts, options that differ, findings matched, both side by side in 3D, and
// their twist curves overlaid.
import * as api from "./api.js";
import { h } from "./dom.js";
import { MARGIN } from "./charts.js";
import { compareViews } from "./compare3d.js";
import { fmt, idleChecks, matchFindings, optionsDiff, runOptionsLabel } from "./format.js";
import { loadPlotly, untabbableModebar } from "./plotly.js";
import { refocus } from "./take-layout.js";

// Each choice starts the view again: an older call still waiting for its answers must not
// draw after a newer one (two comparisons stacked on the page).
let drawing = 0;
// The run chosen in A's or B's picker ({name, value}), until the view it opens has its picker.
let picked = null;

export async function compareView(main, params, onTeardown = () => {}) {
  const mine = ++drawing;
  const options = await runChoices();
  if (mine !== drawing) return;
  main.replaceChildren(h("h1", {}, "Compare two takes or runs"), h("div", { class: "controls" }, runPick("a", params, options), runPick("b", params, options)));
  const ids = [params.get("a"), params.get("b")].filter(Boolean);
  const results = await Promise.all(ids.map(async (id) => ({ run: await api.getRun(id), result: await api.getResult(id).catch(() => null) })));
  if (!results.length || mine !== drawing) return;
  const label = (r) => options.find(([v]) => v === r.run.id)?.[1] || r.run.id;
  main.append(metricsTable(results, label));
  if (results.length < 2 || !results[0].result || !results[1].result) return;
  const [a, b] = results.map((r) => r.result);
  main.append(...optionsDiffPanel(a, b));
  await compareViews(main, results[0], results[1], results.map(label), onTeardown);
  if (mine !== drawing) return;
  main.append(...matchedFindingsPanel(a, b));
  if (await twistOverlay(main, a, b, () => mine !== drawing)) main.dataset.ready = "1";
}

/** Every run of every take (up to 500 takes), as [run id, label] choices. */
async function runChoices() {
  const [page, described] = await Promise.all([api.listTakes({ limit: 500 }), api.getRunOptions()]);
  const takes = await Promise.all(page.items.map((t) => api.getTake(t.id)));
  const options = [];
  takes.forEach((take, k) => take.runs.forEach((r, i) => options.push([r.id,
    `${page.items[k].name} (${String(take.id).slice(0, 6)}) · run ${i + 1} (${r.status}) · ${runOptionsLabel(r, described)}`])));
  return options;
}

/** The choice of run `name` ("a" or "b"); a choice opens the view again with it, its picker
 * given the focus back (a keyboard user goes on choosing). Each choice is as wide as the window
 * allows, not as the longest take name (they can be 240 characters): the closed list cuts the
 * name, the open one shows it whole. */
function runPick(name, params, options) {
  const pick = h("select", { id: `compare-${name}`, onchange: (e) => {
    picked = { name, value: e.target.value };
    const next = new URLSearchParams(params); next.set(name, e.target.value); location.hash = `#/compare?${next}`; } },
  h("option", { value: "" }, "choose…"), options.map(([v, l]) => h("option", { value: v, selected: v === params.get(name) }, l)));
  if (picked && picked.name === name && (params.get(name) || "") === picked.value) { picked = null; refocus(pick); }
  return h("label", { class: "compare-pick" }, `${name.toUpperCase()} `, pick);
}

/** The runs' counts side by side, one column per run. */
function metricsTable(results, label) {
  const metric = (name, get) => h("tr", {}, h("td", {}, name), results.map((r) => h("td", {}, r.result ? get(r.result, r.run) : "–")));
  const maxOffset = (res) => {
    const s = res.series.twist && res.series.twist.summaries;
    return s && s.length ? `${fmt(Math.max(...s.map((c) => c.max_abs_offset_deg)), 1)} °` : "–";
  };
  return h("table", { class: "kv", id: "compare-table" },
    h("thead", {}, h("tr", {}, h("th", {}, "metric"), results.map((r) => h("th", {}, label(r))))),
    h("tbody", {},
      metric("frames", (x) => x.summary.n_frames), metric("frame rate (fps)", (x) => fmt(x.summary.fps, 2)),
      metric("duration (s)", (x) => fmt(x.summary.duration_s, 2)), metric("findings", (x) => x.summary.n_findings),
      metric("twist intervals", (x) => x.summary.findings_by_kind.twist || 0),
      metric("twist intervals applied", (x) => `${x.findings.filter((f) => f.kind === "twist" && f.applied).length} (${x.options.twist_apply})`),
      metric("largest removed offset", maxOffset),
      metric("limb spins (reported, not corrected)", (x) => x.summary.findings_by_kind.spin || 0),
      metric("joint-limit intervals", (x) => (x.steps.limits.state === "done" ? x.summary.findings_by_kind.limits || 0 : x.steps.limits.state)),
      metric("foot locks applied", (x) => (x.steps.feet && x.steps.feet.state === "done" ? `${x.findings.filter((f) => f.kind === "skate" && f.applied).length} of ${x.summary.findings_by_kind.skate || 0} skates (${(x.options && x.options.feet_apply) || "none"})` : x.steps.feet ? x.steps.feet.state : "–")),
      metric("filter", (x) => (x.steps.filter.state === "done" ? x.series.filter?.method || x.options.filter_method : x.steps.filter.state)),
      metric("server time (s)", (x, run) => fmt(run.server_time_s, 3))));
}

/** The options the two runs were made with that differ (a check neither run could run, as
 * markers on a motion take, is no difference). */
function optionsDiffPanel(a, b) {
  const diff = optionsDiff(a.options, b.options, idleChecks(a, b));
  return [h("h2", {}, "Options that differ"),
    diff.length ? h("table", { class: "kv", id: "compare-options" }, h("thead", {}, h("tr", {}, h("th", {}, "option"), h("th", {}, "A"), h("th", {}, "B"))),
      h("tbody", {}, diff.map(([k, x, y]) => h("tr", {}, h("td", {}, k), h("td", {}, x), h("td", {}, y)))))
      : h("p", { class: "muted", id: "compare-options" }, "Same options.")];
}

/** The findings of both runs matched: in both, only in A, only in B. */
function matchedFindingsPanel(a, b) {
  const matched = matchFindings(a.findings, b.findings);
  const span = (f) => `${f.start_frame}–${f.end_frame}`;
  const rows = [
    ...matched.both.map(([x, y]) => [x, "both", span(x), span(y)]),
    ...matched.onlyA.map((x) => [x, "only in A", span(x), "–"]),
    ...matched.onlyB.map((y) => [y, "only in B", "–", span(y)]),
  ].sort((p, q) => p[0].start_frame - q[0].start_frame);
  return [h("h2", {}, `Findings: ${matched.both.length} in both, ${matched.onlyA.length} only in A, ${matched.onlyB.length} only in B`),
    h("table", { id: "compare-findings" }, h("thead", {}, h("tr", {}, ["kind", "joint", "in", "frames (A)", "frames (B)"].map((c) => h("th", {}, c)))),
      h("tbody", {}, rows.map(([f, where, x, y]) => h("tr", { "data-match": where }, h("td", {}, f.kind), h("td", {}, f.joint), h("td", {}, where), h("td", {}, x), h("td", {}, y)))))];
}

/** The twist curves of a chain both runs have, A solid and B dashed, with a joint choice. True
 * when the view is complete (no common chain, or the chart drawn); false when a newer view
 * started meanwhile (`stale()`). */
async function twistOverlay(main, a, b, stale) {
  const chainsA = a.series.twist ? a.series.twist.chains : [];
  const chainsB = new Map((b.series.twist ? b.series.twist.chains : []).map((c) => [c.joint, c]));
  const common = chainsA.filter((c) => chainsB.has(c.joint));
  if (!common.length) return true;
  const flagged = new Set([...a.findings, ...b.findings].filter((f) => f.kind === "twist").map((f) => f.joint));
  const joint = h("select", { id: "compare-joint", "aria-label": "joint" }, common.map((c) => h("option", { value: c.joint, selected: c.joint === [...flagged][0] }, c.joint)));
  const chart = h("div", { id: "compare-twist", class: "chart" });
  main.append(h("h2", {}, "Twist θP and removed offset, A solid, B dashed"), h("div", { class: "controls" }, "joint ", joint), h("div", { class: "panel" }, chart));
  const Plotly = await loadPlotly();
  if (stale()) return false;
  const draw = () => {
    const x = chainsA.find((c) => c.joint === joint.value), y = chainsB.get(joint.value);
    const line = (series, frames, name, dash, color, yaxis) => ({ type: "scatter", mode: "lines", x: frames, y: series, name, yaxis, line: { dash, color, width: 1.4 } });
    const data = [
      line(x.theta_p_deg, a.series.twist.frames, "A θP", "solid", "#1f77b4", "y"), line(y.theta_p_deg, b.series.twist.frames, "B θP", "dash", "#ff7f0e", "y"),
      line(x.offset_deg, a.series.twist.frames, "A offset", "solid", "#1f77b4", "y2"), line(y.offset_deg, b.series.twist.frames, "B offset", "dash", "#ff7f0e", "y2"),
    ];
    const layout = { margin: MARGIN, xaxis: { title: { text: "frame" }, anchor: "y2" },
      yaxis: { domain: [0.52, 1], title: { text: "θP (°)" } }, yaxis2: { domain: [0, 0.45], title: { text: "offset (°)" } }, legend: { orientation: "h", y: -0.25 } };
    return Plotly.react(chart, data, layout, { displaylogo: false, responsive: true });
  };
  await draw();
  untabbableModebar(chart);
  joint.addEventListener("change", draw);
  return true;
}
