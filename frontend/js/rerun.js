// Re-run with other options: only the checks a take of this kind can run are offered.
import * as api from "./api.js";
import { h } from "./dom.js";
import { checksFor } from "./format.js";

export function rerunPanel(take, run, filters) {
  const target = take.kind === "motion" ? "rotations" : "keypoints";
  const usable = filters.filter((f) => f.applies_to.includes(target));
  const available = checksFor(take.kind);
  const checks = available.map((c) => h("label", {}, h("input", { type: "checkbox", value: c, name: "check", checked: run.options.checks.includes(c) }), ` ${c}`));
  const twist = take.kind === "motion"
    ? h("select", { id: "twist-method", "aria-label": "twist method" }, ["robust", "paper"].map((m) => h("option", { value: m, selected: m === run.options.twist_method }, m)))
    : null;
  const method = h("select", { id: "filter-method", "aria-label": "filter" }, h("option", { value: "" }, take.kind === "motion" ? "no filter" : "adaptive (default)"),
    usable.map((f) => h("option", { value: f.name, selected: f.name === run.options.filter_method }, f.label)));
  const preset = h("select", { id: "filter-preset", "aria-label": "preset" });
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
    const filterParams = {};
    for (const input of params.querySelectorAll("input")) {
      if (input.value === "") continue;
      const type = input.dataset.type;
      filterParams[input.dataset.param] = type === "str" ? input.value : type === "bool" ? input.value === "true" : Number(input.value);
    }
    try {
      const created = await api.startRun(take.id, {
        checks: checks.map((l) => l.firstChild).filter((c) => c.checked).map((c) => c.value),
        ...(twist ? { twist_method: twist.value } : {}),
        filter_method: method.value || null, filter_preset: preset.value || null, filter_params: filterParams,
      });
      location.hash = api.takeLink(take.id, created.id);
    } catch (e) { message.textContent = e.message; message.className = "error"; }
  } }, "re-run");
  return h("div", { class: "panel", id: "rerun-panel" }, h("h2", {}, "Re-run with other options (earlier runs are kept)"),
    h("div", { class: "controls" }, checks), h("div", { class: "controls" }, twist ? ["twist ", twist] : null, " filter ", method, " preset ", preset),
    params, h("div", { class: "controls" }, start, message));
}
