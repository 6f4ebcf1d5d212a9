// Re-run with other options: a form grouped by check as the server groups them, every group
// and field from the server's one definition of the run options (GET /run-options, from
// pipeline/options.py) and the filter registry (GET /filters), every number with its unit, the
// named presets, and the values checked in the page before anything is sent.
import * as api from "./api.js";
import { h } from "./dom.js";
import { checksFor, takeChecksKind } from "./format.js";
import { formOptions, paramLabel, takeFilters, usablePresets } from "./run-options.js";

const SHOWN_PARAMS = 4; // filter parameters shown before "more parameters"

const unitText = (unit) => (unit ? h("span", { class: "unit" }, unit) : null);

// The rig's roles named by hand (the `mapping` run option, BVH takes): one list of the take's
// joints per role, "automatic" keeping what the rig tables found. Choosing or focusing a joint
// selects it in the 3D views (`onJoint`), so the role can be checked on the skeleton.
function rolesGroup(roleKeys, joints, summary, mapping, onJoint) {
  const found = summary.roles || {};
  const missing = new Set(summary.missing_roles || []);
  const selects = {};
  const rows = roleKeys.map((role) => {
    const automatic = found[role] && !(role in mapping) ? `automatic (${found[role]})` : missing.has(role) ? "automatic (not found)" : "automatic";
    const select = h("select", { id: `mapping-${role}`, "data-role": role },
      h("option", { value: "" }, automatic), joints.map((j) => h("option", { value: j, selected: mapping[role] === j }, j)));
    const show = () => onJoint(select.value || found[role] || null);
    select.addEventListener("change", show);
    select.addEventListener("focus", show);
    selects[role] = select;
    return h("label", { class: "option-field" + (missing.has(role) ? " missing-role" : "") }, h("span", { class: "option-name" }, role.replace(/_/g, " ")), select);
  });
  const note = missing.size
    ? h("p", { class: "error", id: "roles-missing" }, `Roles not found, their checks skipped: ${[...missing].join(", ")}. Pick their joints below.`)
    : h("p", { class: "muted" }, "Every role was found; pick a joint to override one.");
  const box = h("details", { class: "option-advanced", id: "options-roles", open: missing.size > 0 },
    h("summary", {}, "Rig roles (mapping)"),
    h("fieldset", { class: "option-group", "data-group": "roles" }, note, h("div", { class: "option-fields" }, rows)));
  const chosen = () => Object.fromEntries(Object.entries(selects).filter(([, s]) => s.value).map(([role, s]) => [role, s.value]));
  return { box, chosen };
}

// The controls of the form's own fields by their served type; the filter's fields ("filter",
// "filter_preset") are the filter controls below. Numbers are typed as text and checked here (a
// number input would hide a typo as "").
function choiceControl(field, run) {
  const current = run.options[field.name] ?? field.default;
  const choices = field.choices.includes(current) ? field.choices : [...field.choices, current]; // e.g. interval ids "0,3"
  return h("select", { id: `option-${field.name}`, name: field.name, title: field.help }, choices.map((c) => h("option", { value: c, selected: c === current }, c)));
}
const numberControl = (field, run) => h("input", {
  type: "text", inputmode: field.type === "int" ? "numeric" : "decimal", id: `option-${field.name}`, name: field.name, size: 8,
  placeholder: String(field.default), value: run.options[field.name] ?? "", title: field.help,
});
const CONTROLS = { choice: choiceControl, int: numberControl, float: numberControl };

// A parameter of the chosen filter (GET /filters): a yes/no menu or a text box, with its unit.
function paramRow(p, given) {
  const input = p.type === "bool"
    ? h("select", { "data-param": p.name }, h("option", { value: "" }, `default (${p.default})`), ["true", "false"].map((v) => h("option", { value: v, selected: String(given[p.name]) === v }, v)))
    : h("input", { type: "text", inputmode: p.type === "str" ? "text" : "decimal", size: 8, "data-param": p.name, placeholder: String(p.default), value: given[p.name] ?? "" });
  return h("label", { class: "option-field", title: p.name }, h("span", { class: "option-name" }, paramLabel(p.name)), input, unitText(p.unit));
}

// The filter: its method (the registry's filters for this kind of take, and the one run when none
// is chosen, as GET /run-options serves them), the filter's presets and its parameters (with
// units; past the first few, folded), refilled when the method changes. With no filter chosen
// and none by default (a motion take), the check would filter nothing: its box is unticked and
// disabled, and the presets hidden, with the reason, until a filter is chosen.
function filterControls(take, run, filters, described) {
  const { usable, fallback } = takeFilters(takeChecksKind(take, described), described, filters);
  const method = h("select", { id: "filter-method", "aria-label": "filter" }, h("option", { value: "" }, fallback ? `${fallback} (default)` : "no filter"),
    usable.map((f) => h("option", { value: f.name, selected: f.name === run.options.filter_method }, f.label)));
  const preset = h("select", { id: "filter-preset", "aria-label": "filter preset" });
  const params = h("div", { id: "filter-params", class: "option-fields" });
  const none = h("p", { class: "muted", id: "filter-none" }, "No filter chosen, and this kind of take has no default one: the check would filter nothing. Choose a filter to use it.");
  let paramFields = [];
  let box = null; // the filter check's box, once the form has it
  const sync = () => {
    const entry = usable.find((f) => f.name === (method.value || fallback)) || null;
    const row = preset.closest("label");
    // Inline: the fields' stylesheet display would win over `hidden`.
    if (row) row.style.display = !entry || !entry.presets.length ? "none" : "";
    none.style.display = entry ? "none" : "";
    if (!box) return;
    box.disabled = !entry;
    if (!entry) box.checked = false;
    box.title = entry ? "" : "choose a filter first";
  };
  const fill = () => {
    const entry = usable.find((f) => f.name === (method.value || fallback)) || null;
    preset.replaceChildren(...(entry ? entry.presets : []).map((p) => h("option", { value: p, selected: p === run.options.filter_preset }, p)));
    sync();
    paramFields = entry ? entry.parameters : [];
    const given = method.value === (run.options.filter_method || "") ? run.options.filter_params || {} : {};
    const rows = paramFields.map((p) => paramRow(p, given));
    const more = rows.length > SHOWN_PARAMS
      ? [h("details", { class: "more-params" }, h("summary", {}, `${rows.length - SHOWN_PARAMS} more parameters`), h("div", { class: "option-fields" }, rows.slice(SHOWN_PARAMS)))]
      : [];
    params.replaceChildren(none, ...rows.slice(0, SHOWN_PARAMS), ...more);
  };
  method.addEventListener("change", fill);
  fill();
  const values = () => ({
    filter_method: method.value, filter_preset: preset.value,
    params: [...params.querySelectorAll("[data-param]")].map((input) => [paramFields.find((p) => p.name === input.dataset.param), input.value]),
  });
  /** Tie the filter check's box (absent when the take cannot run the check) to the method. */
  const attach = (checkBox) => { box = checkBox || null; sync(); };
  return { method, preset, params, fill, attach, values, controls: { filter: method, filter_preset: preset } };
}

// One group of the form as served: its check's box (only for a check this take can run), its
// fields' controls (kept in `form.inputs` by option name) and, with no fields, the group's note.
function groupBox(g, form) {
  const check = g.check && form.available.includes(g.check)
    ? h("input", { type: "checkbox", name: "check", value: g.check, checked: form.run.options.checks.includes(g.check) }) : null;
  if (g.check && !check) return null; // a check this kind of take cannot run
  if (check) form.checks[g.check] = check;
  const rows = g.fields.map((f) => {
    const control = form.filter.controls[f.type] || (form.inputs[f.name] = CONTROLS[f.type](f, form.run));
    return h("label", { class: "option-field", title: f.help }, h("span", { class: "option-name" }, f.label), control, unitText(f.unit));
  });
  const hasFilter = g.fields.some((f) => f.type in form.filter.controls);
  const body = rows.length ? [h("div", { class: "option-fields" }, rows), hasFilter ? form.filter.params : null] : h("p", { class: "muted" }, g.note || "");
  const legend = h("legend", {}, check ? h("label", {}, check, ` ${g.label}`) : g.label);
  const set = h("fieldset", { class: "option-group", "data-group": g.name }, g.advanced ? null : legend, body);
  return g.advanced ? h("details", { class: "option-advanced", id: `options-${g.name}` }, h("summary", {}, g.label), set) : set;
}

// Presets fill the form; every field stays editable.
function presetPicker(described, form) {
  const presets = usablePresets(described.presets, form.available);
  const pick = h("select", { id: "run-preset", "aria-label": "options preset" }, h("option", { value: "" }, "— as this run —"),
    presets.map(([name]) => h("option", { value: name }, name)));
  pick.addEventListener("change", () => {
    const chosen = presets.find(([name]) => name === pick.value);
    if (!chosen) return;
    const options = chosen[1];
    for (const [name, box] of Object.entries(form.checks)) box.checked = options.checks.includes(name);
    for (const [name, control] of Object.entries(form.inputs)) control.value = options[name] ?? "";
    const { method } = form.filter;
    if ([...method.options].some((o) => o.value === (options.filter_method || ""))) method.value = options.filter_method || "";
    form.filter.fill();
  });
  return pick;
}

// The form's values checked in the page: refused, the fields at fault are marked and the first
// takes the focus; else the run starts and the page goes to it.
async function startRun(take, form, fields, message) {
  for (const el of document.querySelectorAll("#rerun-panel [aria-invalid]")) el.removeAttribute("aria-invalid");
  const values = {
    checks: Object.entries(form.checks).filter(([, box]) => box.checked).map(([name]) => name),
    ...Object.fromEntries(Object.entries(form.inputs).map(([name, control]) => [name, control.value])),
    ...form.filter.values(),
    mapping: form.roles ? form.roles.chosen() : undefined,
  };
  const built = formOptions(values, fields);
  if (built.errors) {
    for (const error of built.errors) {
      const name = error.split(":")[0];
      const bad = form.filter.params.querySelector(`[data-param="${CSS.escape(name)}"]`) || form.inputs[name];
      if (bad) bad.setAttribute("aria-invalid", "true");
    }
    message.textContent = built.errors.join(" · "); message.className = "error";
    // The first field at fault takes the focus, so the keyboard is where the fix goes.
    document.querySelector("#rerun-panel [aria-invalid='true']")?.focus();
    return;
  }
  try {
    const created = await api.startRun(take.id, built.options);
    location.hash = api.takeLink(take.id, created.id);
  } catch (e) { message.textContent = e.message; message.className = "error"; }
}

// A change to the form answers an earlier refusal: its message and marks go (they named fields
// that may be gone, e.g. after choosing a preset).
function clearOnChange(panel, message) {
  const clear = () => {
    if (message.className !== "error") return;
    message.textContent = ""; message.className = "muted";
    for (const el of panel.querySelectorAll("[aria-invalid]")) el.removeAttribute("aria-invalid");
  };
  panel.addEventListener("change", clear);
  panel.addEventListener("input", clear);
}

/** The re-run panel of a take: `described` is GET /run-options, `filters` GET /filters. */
export function rerunPanel(take, run, filters, described, context = {}) {
  const available = checksFor(take, described).filter((c) => described.checks.includes(c));
  const fields = Object.fromEntries(described.groups.flatMap((g) => g.fields).map((f) => [f.name, f]));
  const joints = (take.reading && take.reading.joints) || [];
  const form = {
    run, available, filter: filterControls(take, run, filters, described),
    inputs: {}, // option name -> its control
    checks: {}, // check name -> its box
    roles: take.kind === "motion" && context.summary && joints.length && described.role_keys
      ? rolesGroup(described.role_keys, joints, context.summary, run.options.mapping || {}, context.onJoint || (() => {}))
      : null,
  };
  const groups = described.groups.map((g) => groupBox(g, form));
  form.filter.attach(form.checks.filter);
  const presetPick = presetPicker(described, form);
  const message = h("span", { class: "muted", id: "rerun-message", role: "status" });
  const start = h("button", { class: "primary", id: "rerun", onclick: () => startRun(take, form, fields, message) }, "re-run");
  const panel = h("div", { class: "panel", id: "rerun-panel" }, h("h2", {}, "Re-run with other options (earlier runs are kept)"),
    h("div", { class: "controls" }, h("label", {}, "preset ", presetPick)),
    h("div", { class: "option-groups" }, groups, form.roles ? form.roles.box : null), h("div", { class: "controls" }, start, message));
  clearOnChange(panel, message);
  return panel;
}
