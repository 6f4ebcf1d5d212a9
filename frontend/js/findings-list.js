// The findings list of the take view: grouped by joint (collapsible groups with counts and the
// worst value), sortable, filtered by kind, joint, smallest value and text. N/P walk the
// findings the filters keep, across groups; the one reached is marked and its group opened.
import { activatable, h } from "./dom.js";
import { fmt, sortFindings } from "./format.js";
import { filterFindings, filterParams, groupByJoint, jointsOf, kindsOf, listOrder } from "./findings.js";

const COLUMNS = [["kind", "kind"], ["joint", "joint"], ["start_frame", "frames"], ["duration", "frames long"], ["value", "offset / spin / outside"], ["confidence", "confidence"]];
const UNITS = { deg: "°" };
const unitOf = (f) => UNITS[f.unit] ?? f.unit ?? "";

/** The filter fields (kinds, joint, smallest value, words) and the "group by joint" box;
 * `filter` is changed in place and `refilter()` called, `onGroup(on)` for the box. */
function filterControls(findings, filter, units, refilter, onGroup) {
  const kindBoxes = kindsOf(findings).map((k) => {
    const box = h("input", { type: "checkbox", id: `filter-kind-${k}`, value: k, checked: !filter.kinds.size || filter.kinds.has(k) });
    box.addEventListener("change", () => {
      filter.kinds = new Set(kindBoxes.filter((b) => b.checked).map((b) => b.value));
      if (!filter.kinds.size) filter.kinds = new Set(["none"]); // nothing ticked shows nothing
      refilter();
    });
    return box;
  });
  const joint = h("select", { id: "filter-joint", "aria-label": "joint filter" }, h("option", { value: "" }, "all joints"),
    jointsOf(findings).map((j) => h("option", { value: j, selected: j === filter.joint }, j)));
  joint.addEventListener("change", () => { filter.joint = joint.value; refilter(); });
  const least = h("input", { type: "number", id: "filter-min", min: 0, step: "any", size: 5, value: filter.minValue ?? "", "aria-label": `smallest offset or distance outside (${units})` });
  least.addEventListener("input", () => { filter.minValue = least.value === "" ? null : Number(least.value); refilter(); });
  const text = h("input", { type: "search", id: "filter-text", value: filter.text, placeholder: "search joint, kind, frames…", "aria-label": "search findings" });
  text.addEventListener("input", () => { filter.text = text.value; refilter(); });
  const groupBox = h("input", { type: "checkbox", id: "group-joints", checked: true });
  groupBox.addEventListener("change", () => onGroup(groupBox.checked));
  return h("div", { class: "controls findings-filters" },
    kindBoxes.map((b) => h("label", {}, b, ` ${b.value}`)),
    joint,
    h("label", {}, "at least ", least, ` ${units}`),
    text,
    h("label", {}, groupBox, " group by joint"));
}

/** The table's header: a click (Enter) on a column sorts by it, again reverses (`sort` is
 * changed in place, then `render()`). */
function sortHead(sort, decided, render) {
  const sortHeader = ([k, label]) => activatable(h("th", { class: "sortable", "data-key": k, "aria-sort": "none" }, label), (e) => {
    sort.dir = sort.key === k ? -sort.dir : 1; sort.key = k;
    for (const th of e.currentTarget.parentNode.children) th.setAttribute("aria-sort", "none");
    e.currentTarget.setAttribute("aria-sort", sort.dir > 0 ? "ascending" : "descending");
    render();
  });
  return h("thead", {}, h("tr", {}, COLUMNS.map(sortHeader), decided.enabled ? h("th", {}, "applied · decision") : null));
}

/** One finding's row; `open()` on a click or Enter. */
function findingRow(f, isCurrent, decided, open) {
  return activatable(h("tr", {
    class: `clickable finding${isCurrent ? " current" : ""}`, "data-start": f.start_frame, "data-joint": f.joint, "data-kind": f.kind,
    "data-interval": f.kind === decided.kind ? f.id : null, "data-lock": decided.isLock?.(f) ? f.id : null,
    "aria-current": isCurrent ? "true" : null,
  },
  h("td", {}, f.kind), h("td", {}, f.joint, f.readout ? h("div", { class: "muted readout" }, f.readout) : null), h("td", { class: "frames" }, `${f.start_frame}–${f.end_frame}`), h("td", {}, f.end_frame - f.start_frame + 1),
  h("td", { class: "value" }, f.value == null ? "–" : `${fmt(f.value, 1)} ${unitOf(f)}`), h("td", {}, f.kind === "twist" ? `${fmt(100 * f.confidence, 0)} %` : fmt(f.confidence, 2)),
  decided.enabled ? decided.cell(f) : null), open);
}

/** A joint's group heading (count, worst value, kinds); `toggle()` opens or closes the group. */
function groupHeadRow(g, open, span, toggle) {
  const unit = unitOf(g.rows[0]);
  return activatable(h("tr", { class: "group-head", "data-joint": g.joint, "aria-expanded": String(open) },
    h("th", { colspan: span },
      h("span", { class: "caret", "aria-hidden": "true" }, open ? "▾ " : "▸ "), h("b", {}, g.joint),
      ` · ${g.count} finding${g.count === 1 ? "" : "s"}`,
      g.worst == null ? "" : ` · worst ${fmt(g.worst, 1)} ${unit}`, ` · ${[...g.kinds].join(", ")}`)), toggle);
}

/**
 * @param findings  the run's findings
 * @param decided   the decisions (cells of twist, swap and foot-lock rows, footer)
 * @param onOpen    called with a finding opened by a click or Enter
 * @param initial   the filter to start with ({kinds, joint, minValue, text}, as filterFromParams)
 * @param onFilter  called with the filter's link parameters (filterParams) when it changes
 */
export function findingsList(findings, decided, onOpen, initial = null, onFilter = () => {}) {
  const sort = { key: "start_frame", dir: 1 };
  let grouped = true, current = null;
  const collapsed = new Set();
  const filter = { kinds: new Set(), joint: "", minValue: null, text: "", ...initial };
  const allKinds = kindsOf(findings);
  let shown = findings;
  const table = h("table", { id: "findings" });
  const title = h("h2", {}, "");
  const units = [...new Set(findings.map(unitOf))].filter(Boolean).join(" / ");
  const controls = filterControls(findings, filter, units, () => { render(); onFilter(filterParams(filter, allKinds)); },
    (on) => { grouped = on; render(); });
  const head = sortHead(sort, decided, () => render());
  const span = COLUMNS.length + (decided.enabled ? 1 : 0);
  const row = (f) => findingRow(f, f === current, decided, () => { mark(f); onOpen(f); });
  const groupHead = (g) => groupHeadRow(g, !collapsed.has(g.joint), span, () => {
    if (collapsed.has(g.joint)) collapsed.delete(g.joint); else collapsed.add(g.joint);
    render();
    table.querySelector(`tr.group-head[data-joint="${CSS.escape(g.joint)}"]`)?.focus();
  });

  function render() {
    shown = filterFindings(findings, filter);
    title.textContent = shown.length === findings.length ? `Findings (${findings.length})` : `Findings (${shown.length} of ${findings.length} shown)`;
    const bodies = grouped
      ? groupByJoint(shown, sort.key, sort.dir).map((g) => h("tbody", { class: "group", "data-joint": g.joint }, groupHead(g), collapsed.has(g.joint) ? null : g.rows.map(row)))
      : [h("tbody", {}, sortFindings(shown, sort.key, sort.dir).map(row))];
    // Filters that keep nothing say so (a bare header read as a broken table).
    const none = findings.length && !shown.length
      ? [h("tbody", {}, h("tr", { id: "findings-none" }, h("td", { colspan: span, class: "muted" }, "No finding matches the filters.")))]
      : [];
    table.replaceChildren(head, ...bodies, ...none);
  }

  /** Mark `f` as the current finding: its row highlighted, its group opened. */
  function mark(f) {
    current = f;
    if (f && collapsed.delete(f.joint)) render();
    for (const tr of table.querySelectorAll("tr.finding")) {
      // A twist and a limits finding may share joint and start: the kind tells them apart.
      const on = tr.dataset.start === String(f?.start_frame) && tr.dataset.joint === f?.joint && tr.dataset.kind === f?.kind;
      tr.classList.toggle("current", on);
      if (on) tr.setAttribute("aria-current", "true"); else tr.removeAttribute("aria-current");
    }
  }

  render();
  // Every row and its buttons are Tab stops: a way past them to the take's review.
  const skip = h("button", { class: "small", id: "skip-to-review", onclick: () => document.getElementById("review-status")?.focus() }, "skip to the review ↓");
  const panel = h("div", { class: "panel", id: "findings-panel" }, title, findings.length ? skip : null,
    findings.length ? [controls, table] : h("p", { class: "muted" }, "No findings."),
    decided.footer());
  return {
    panel,
    /** The findings the filters keep, in list order. */
    get shown() { return grouped ? listOrder(groupByJoint(shown, sort.key, sort.dir)) : sortFindings(shown, sort.key, sort.dir); },
    mark,
    get current() { return current; },
  };
}
