// The shoot view's take table: its filter bar, the sortable table of one page of takes and the
// pager. The table is sorted, filtered and paged on the server; a poll redraws it in place.
import * as api from "./api.js";
import { activatable, badge, h, REVIEW } from "./dom.js";
import { formatCell, nextSort, pageInfo, scoreColor, scoreRangeProblem, TAKE_COLUMNS, takesQuery } from "./shoot-format.js";

const ALL_COLUMNS_KEY = "mocapqa-shoot-all-columns"; // the take table's "all columns" choice, kept in the browser

/** The take table's filters. Every field has a visible label (a typed number says nothing by
 * itself); a score range that can match no take is said at once beside the fields. The
 * "all columns" toggle shows the columns a narrow window hides (the table then scrolls in
 * its box). */
export function filterBar(state, apply, allColumns) {
  const select = (key, label, options) => h("label", {}, `${label} `, h("select", { id: `shoot-${key}`, onchange: (e) => apply({ [key]: e.target.value }) },
    options.map(([v, text]) => h("option", { value: v, selected: String(state[key]) === v }, text))));
  const fields = {};
  const input = (key, attrs, onInput = () => {}) => {
    const el = h("input", { id: `shoot-${key}`, value: state[key], ...attrs });
    let timer = null;
    el.addEventListener("input", () => { onInput(); clearTimeout(timer); timer = setTimeout(() => apply({ [key]: el.value }), 350); });
    fields[key] = el;
    return el;
  };
  const scoreMessage = h("span", { id: "shoot-score-message", role: "alert" });
  const checkScores = () => {
    const problem = scoreRangeProblem({ min_score: fields.min_score.value, max_score: fields.max_score.value });
    for (const key of ["min_score", "max_score"]) fields[key].setAttribute("aria-invalid", String(!!problem && problem.fields.includes(key)));
    scoreMessage.textContent = problem ? problem.text : "";
    scoreMessage.className = problem ? "error" : "";
  };
  const labelled = (label, el) => h("label", { for: el.id }, `${label} `, el);
  const bar = h("div", { class: "controls shoot-filters" },
    input("search", { type: "search", "aria-label": "search name", placeholder: "search name" }),
    select("status", "run", [["", "any"], ["queued", "queued"], ["running", "running"], ["done", "done"], ["failed", "failed"]]),
    select("review_status", "review", [["", "any"], ...Object.entries(REVIEW)]),
    select("has_findings", "findings", [["", "any"], ["true", "some"], ["false", "none"]]),
    select("has_skates", "foot skates", [["", "any"], ["true", "some"], ["false", "none"]]),
    labelled("rig", input("rig", { class: "short" })),
    labelled("min score", input("min_score", { type: "number", min: 0, max: 100, step: "any", placeholder: "0", class: "short" }, () => checkScores())),
    labelled("max score", input("max_score", { type: "number", min: 0, max: 100, step: "any", placeholder: "100", class: "short" }, () => checkScores())),
    scoreMessage, allColumns);
  checkScores();
  return bar;
}

/** The "all columns" toggle (shown only where the window hides columns): a pressed button that
 * marks the table area, the choice kept in the browser. */
export function allColumnsToggle(area) {
  const button = h("button", { type: "button", id: "shoot-all-columns", class: "columns-toggle", "aria-pressed": "false",
    title: "show the duration, rig, spins, worst joint, filter, missing, below floor, floating and reviewer columns too (the table scrolls sideways in its box)" }, "all columns");
  const set = (on) => {
    button.setAttribute("aria-pressed", String(on));
    area.classList.toggle("all-columns", on);
  };
  let stored = null;
  try { stored = localStorage.getItem(ALL_COLUMNS_KEY); } catch { /* storage refused: not kept */ }
  set(stored === "1");
  button.addEventListener("click", () => {
    const on = button.getAttribute("aria-pressed") !== "true";
    set(on);
    try { localStorage.setItem(ALL_COLUMNS_KEY, on ? "1" : "0"); } catch { /* storage refused: not kept */ }
  });
  return button;
}

/** A selector finding again, after a redraw of `box`, the element of it that has the focus:
 * by a header's column, a row's take or the element's id (null when the focus is elsewhere). */
function focusedIn(box) {
  const el = document.activeElement;
  if (!el || el === box || !box.contains(el)) return null;
  if (el.dataset.sort) return `th[data-sort="${CSS.escape(el.dataset.sort)}"]`;
  if (el.dataset.take) return `tr[data-take="${CSS.escape(el.dataset.take)}"]`;
  return el.id ? `#${CSS.escape(el.id)}` : null;
}

function takeTable(page, state, apply) {
  const header = TAKE_COLUMNS.map((c) => {
    const sorted = state.sort === c.key;
    const th = h("th", { class: `sortable${c.narrow ? " narrow-hide" : ""}`, "data-sort": c.key, "aria-sort": sorted ? (state.order === "asc" ? "ascending" : "descending") : "none", title: c.title || null },
      c.label, sorted ? (state.order === "asc" ? " ▲" : " ▼") : "");
    // From the state when clicked, not when drawn: two clicks before the answer toggle twice.
    return activatable(th, () => apply((now) => nextSort(now, c.key)));
  });
  const rows = page.items.map((t) => activatable(h("tr", { class: "clickable", "data-take": t.take_id, "aria-label": `open ${t.name}` },
    h("td", { class: "thumb-cell" }, t.status === "done" ? h("img", { class: "thumb", src: api.thumbnailUrl(t.take_id, t.run_id), alt: "" }) : null),
    TAKE_COLUMNS.map((c) => {
      const text = formatCell(c.key, t);
      const cell = c.key === "status" ? badge(text) : c.key === "review_status" ? badge(text, t.review_status)
        : c.key === "score" ? h("span", { class: "score", style: null, "data-score": t.score ?? "" }, text) : text;
      const classes = [c.key === "name" ? "name" : "", c.narrow ? "narrow-hide" : "", c.wraps ? "wraps" : ""].filter(Boolean);
      const td = h("td", { class: classes.join(" ") || null }, cell);
      if (c.key === "score") td.firstChild.style.color = scoreColor(t.score);
      return td;
    })), () => { location.hash = api.takeLink(t.take_id, t.run_id); }));
  // The order in words too: a narrow window hides some sorted columns' headers.
  const by = TAKE_COLUMNS.find((c) => c.key === state.sort);
  const caption = h("caption", { id: "shoot-sort", class: "muted" }, by ? `sorted by ${by.label} ${state.order === "asc" ? "▲" : "▼"}` : "");
  return h("div", { class: "table-scroll" }, h("table", { id: "shoot-takes" }, caption,
    h("thead", {}, h("tr", {}, h("th", {}, ""), header)), h("tbody", {}, rows)));
}

/** The table's pager: previous, which takes are shown, next. */
function pager(info, apply) {
  const move = (offset) => h("button", { disabled: offset == null, onclick: () => apply({ offset }) });
  const previous = move(info.previous); previous.append("‹ previous"); previous.id = "page-previous";
  const next = move(info.next); next.append("next ›"); next.id = "page-next";
  return h("div", { class: "controls" }, previous, h("span", { id: "page-info" }, info.text), next);
}

/**
 * The take table in `area` (filter bar above, table and pager in `box`).
 *
 * @param getState  the table's state now (tableState)
 * @param apply     changes the state (a patch, or a function of the state to a patch)
 * @param isAlive   false once the view is gone: a late answer draws nothing
 * @returns {draw()} draw the table again (the latest request wins)
 */
export function createTakeTable(shootId, area, box, getState, apply, isAlive) {
  let drawn = 0; // the latest table request: an older answer arriving late is dropped
  const draw = async () => {
    const request = ++drawn;
    const state = getState();
    const problem = scoreRangeProblem(state);
    if (problem) { // no take can match: no request, and no silent "0–0 of 0" (the filter bar says why)
      box.replaceChildren(h("p", { class: "muted", id: "shoot-table-empty" }, "No takes listed: the score range above matches none."));
      area.dataset.query = takesQuery(state);
      return;
    }
    const page = await api.shootTakes(shootId, takesQuery(state));
    if (!isAlive() || request !== drawn) return;
    // The filter bar stays (a poll must not take the focus from the search field); the table
    // and pager are redrawn, and what had the focus in them keeps it: the same header, the
    // same take's row (polled every second while takes are analysed), the same pager button.
    const focused = focusedIn(box);
    box.replaceChildren(takeTable(page, state, apply), pager(pageInfo(state.offset, state.limit, page.total), apply));
    if (focused) {
      const again = box.querySelector(focused);
      if (again && !again.disabled) again.focus({ preventScroll: true });
    }
    area.dataset.query = takesQuery(state);
  };
  return { draw };
}
