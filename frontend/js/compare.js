// Compare two runs: their counts and options side by side.
import * as api from "./api.js";
import { h } from "./dom.js";
import { fmt } from "./format.js";

export async function compareView(main, params) {
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
