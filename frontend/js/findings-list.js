// The findings list of the take view: grouped by joint (collapsible groups with counts and the
// worst value of each unit), sortable, filtered by kind, joint, smallest value (in one unit) and
// text. N/P walk the findings the filters keep, across groups; the one reached is marked and
// its group opened. The filter and the order travel in the link.
import { activatable, h } from "./dom.js";
import { fmt, sortFindings } from "./format.js";
import {
  confidenceText, filterFindings, filterParams, groupByJoint, jointsOf, kindsOf, listOrder, listSortKeys, unitLabel, unitOf, unitsOf, usedProbability, worstText,
} from "./findings.js";

const COLUMNS = [["kind", "kind"], ["joint", "joint"], ["start_frame", "frames"], ["duration", "frames long"], ["value", "offset / spin / outside"], ["confidence", "confidence"]];

/** The "at least" field: a number and the unit it applies to (a menu when the findings come in
 * several units; findings in the other units are then hidden, as the note beside it says). */
function leastControls(filter, units, refilter) {
  const least = h("input", { type: "number", id: "filter-min", min: 0, step: "any", size: 5, value: filter.minValue ?? "" });
  const unit = units.length > 1
    ? h("select", { id: "filter-min-unit", "aria-label": "unit of the smallest value" }, units.map((u) => h("option", { value: u, selected: u === filter.unit }, unitLabel(u))))
    : h("span", { id: "filter-min-unit" }, unitLabel(units[0]));
  const note = h("span", { class: "muted", id: "filter-min-note" });
  const label = () => {
    const shown = unitLabel(filter.unit);
    least.setAttribute("aria-label", `smallest value, in ${shown}${units.length > 1 ? " (findings in other units hidden)" : ""}`);
    note.textContent = units.length > 1 && filter.minValue != null ? ` only findings in ${shown}` : "";
  };
  least.addEventListener("input", () => { filter.minValue = least.value === "" ? null : Number(least.value); label(); refilter(); });
  unit.addEventListener("change", () => { filter.unit = unit.value; label(); refilter(); });
  label();
  return h("label", { class: "filter-least" }, "at least ", least, " ", unit, note);
}

/** The filter fields (kinds, joint, smallest value, words) and the "group by joint" box;
 * `filter` is changed in place and `refilter()` called, `onGroup(on)` for the box. */
function filterControls(findings, filter, refilter, onGroup) {
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
  const units = unitsOf(findings);
  const text = h("input", { type: "search", id: "filter-text", value: filter.text, placeholder: "search joint, kind, frames…", "aria-label": "search findings" });
  text.addEventListener("input", () => { filter.text = text.value; refilter(); });
  const groupBox = h("input", { type: "checkbox", id: "group-joints", checked: true });
  groupBox.addEventListener("change", () => onGroup(groupBox.checked));
  return h("div", { class: "controls findings-filters" },
    kindBoxes.map((b) => h("label", {}, b, ` ${b.value}`)),
    joint,
    units.length ? leastControls(filter, units, refilter) : null,
    text,
    h("label", {}, groupBox, " group by joint"));
}

/** The table's header: a click (Enter or Space) on a column sorts by it, again reverses (`sort`
 * is changed in place, then `onSort()`). The header stays in the table, so its focus stays. */
function sortHead(sort, decided, onSort) {
  const ariaSort = (k) => (sort.key !== k ? "none" : sort.dir > 0 ? "ascending" : "descending");
  const sortHeader = ([k, label]) => activatable(h("th", { class: "sortable", "data-key": k, "aria-sort": ariaSort(k) }, label), (e) => {
    sort.dir = sort.key === k ? -sort.dir : 1; sort.key = k;
    for (const th of e.currentTarget.parentNode.querySelectorAll("th.sortable")) th.setAttribute("aria-sort", ariaSort(th.dataset.key));
    onSort();
  });
  return h("thead", {}, h("tr", {}, COLUMNS.map(sortHeader), decided.enabled ? h("th", {}, "applied · decision") : null));
}

/** One finding's row; `open()` on a click or Enter. `used`: the probability a twist interval's
 * decision used, when a reviewer prior moved it (usedProbability). */
function findingRow(f, isCurrent, decided, used, open) {
  const confidence = h("td", { class: "confidence" }, confidenceText(f, used));
  if (used != null) confidence.title = `calibrated probability ${fmt(f.confidence, 2)}, moved to ${fmt(used, 2)} by the shoot's reviewers' decisions: the decision used ${fmt(used, 2)}`;
  return activatable(h("tr", {
    class: `clickable finding${isCurrent ? " current" : ""}`, "data-start": f.start_frame, "data-joint": f.joint, "data-kind": f.kind,
    "data-interval": f.kind === decided.kind ? f.id : null, "data-lock": decided.isLock?.(f) ? f.id : null,
    "aria-current": isCurrent ? "true" : null,
  },
  h("td", {}, f.kind), h("td", {}, f.joint, f.readout ? h("div", { class: "muted readout" }, f.readout) : null), h("td", { class: "frames" }, `${f.start_frame}–${f.end_frame}`), h("td", {}, f.end_frame - f.start_frame + 1),
  h("td", { class: "value" }, f.value == null ? "–" : `${fmt(f.value, 1)} ${unitLabel(unitOf(f))}`), confidence,
  decided.enabled ? decided.cell(f) : null), open);
}

/** A joint's group heading (count, worst value of each unit, kinds); `toggle()` opens or closes the group. */
function groupHeadRow(g, open, span, toggle) {
  const worst = worstText(g);
  return activatable(h("tr", { class: "group-head", "data-joint": g.joint, "aria-expanded": String(open) },
    h("th", { colspan: span },
      h("span", { class: "caret", "aria-hidden": "true" }, open ? "▾ " : "▸ "), h("b", {}, g.joint),
      ` · ${g.count} finding${g.count === 1 ? "" : "s"}`,
      worst ? ` · worst ${worst}` : "", ` · ${[...g.kinds].join(", ")}`)), toggle);
}

/**
 * @param findings  the run's findings
 * @param decided   the decisions (cells of twist, swap and foot-lock rows, footer)
 * @param onOpen    called with a finding opened by a click or Enter
 * @param initial   the filter and order to start with ({kinds, joint, minValue, unit, text,
 *                  sortKey, sortDir}, as filterFromParams)
 * @param onFilter  called with the filter's and order's link parameters (filterParams) when
 *                  they change
 * @param twist     the run's `series.twist` (its intervals' evidence: the probability each
 *                  decision used), or null
 */
export function findingsList(findings, decided, onOpen, initial = null, onFilter = () => {}, twist = null) {
  const units = unitsOf(findings);
  const filter = { kinds: new Set(), joint: "", minValue: null, unit: "", text: "", sortKey: "start_frame", sortDir: 1, ...initial };
  if (!units.includes(filter.unit)) filter.unit = units[0] ?? "";
  const sort = { key: filter.sortKey, dir: filter.sortDir };
  let grouped = true, current = null;
  const collapsed = new Set();
  const allKinds = kindsOf(findings);
  const intervals = twist && twist.intervals ? new Map(twist.intervals.map((i) => [i.id, i])) : null;
  const keys = listSortKeys(intervals);
  let shown = findings;
  const table = h("table", { id: "findings" });
  const title = h("h2", {}, "");
  const changed = () => { render(); onFilter(filterParams(filter, allKinds)); };
  const controls = filterControls(findings, filter, changed, (on) => { grouped = on; render(); });
  const head = sortHead(sort, decided, () => { filter.sortKey = sort.key; filter.sortDir = sort.dir; changed(); });
  const span = COLUMNS.length + (decided.enabled ? 1 : 0);
  const row = (f) => findingRow(f, f === current, decided, usedProbability(f, intervals), () => { mark(f); onOpen(f); });
  const groupHead = (g) => groupHeadRow(g, !collapsed.has(g.joint), span, () => {
    if (collapsed.has(g.joint)) collapsed.delete(g.joint); else collapsed.add(g.joint);
    render();
    table.querySelector(`tr.group-head[data-joint="${CSS.escape(g.joint)}"]`)?.focus();
  });
  const groups = () => groupByJoint(shown, sort.key, sort.dir, keys);

  function render() {
    shown = filterFindings(findings, filter);
    title.textContent = shown.length === findings.length ? `Findings (${findings.length})` : `Findings (${shown.length} of ${findings.length} shown)`;
    const bodies = grouped
      ? groups().map((g) => h("tbody", { class: "group", "data-joint": g.joint }, groupHead(g), collapsed.has(g.joint) ? null : g.rows.map(row)))
      : [h("tbody", {}, sortFindings(shown, sort.key, sort.dir, keys).map(row))];
    // Filters that keep nothing say so (a bare header read as a broken table).
    const none = findings.length && !shown.length
      ? [h("tbody", {}, h("tr", { id: "findings-none" }, h("td", { colspan: span, class: "muted" }, "No finding matches the filters.")))]
      : [];
    // The header stays where it is (taken out and put back, it would lose the focus).
    if (head.parentNode !== table) table.prepend(head);
    for (const el of [...table.children]) if (el !== head) el.remove();
    table.append(...bodies, ...none);
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
    get shown() { return grouped ? listOrder(groups()) : sortFindings(shown, sort.key, sort.dir, keys); },
    mark,
    get current() { return current; },
  };
}
