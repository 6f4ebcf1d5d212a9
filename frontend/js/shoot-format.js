// Pure functions of the shoot view: the take table's query string, column formatting, score
// colours, progress, import results and the review keys. No DOM: unit-tested with node --test.
import { fmt } from "./format.js";

/** Filters and paging the take table understands, with their defaults (the server's). */
export const TABLE_DEFAULTS = {
  sort: "score", order: "asc", limit: 25, offset: 0,
  status: "", review_status: "", rig: "", min_score: "", max_score: "", has_findings: "", has_skates: "", search: "",
};

/** The take table's filters (the keys of TABLE_DEFAULTS that narrow the takes). */
export const TABLE_FILTERS = ["status", "review_status", "rig", "min_score", "max_score", "has_findings", "has_skates", "search"];

/** The table's state from the view's URL parameters (unknown keys ignored, numbers parsed). */
export function tableState(params) {
  const out = { ...TABLE_DEFAULTS };
  for (const key of Object.keys(TABLE_DEFAULTS)) {
    const value = params.get(key);
    if (value != null) out[key] = value;
  }
  out.limit = Math.max(1, Math.min(500, Number.parseInt(out.limit, 10) || TABLE_DEFAULTS.limit));
  out.offset = Math.max(0, Number.parseInt(out.offset, 10) || 0);
  if (out.order !== "asc" && out.order !== "desc") out.order = "asc";
  return out;
}

/** The query string of GET /shoots/{id}/takes (empty filters left out, keys in a fixed order). */
export function takesQuery(state) {
  const query = new URLSearchParams();
  for (const key of Object.keys(TABLE_DEFAULTS)) {
    const value = state[key];
    if (value === "" || value == null) continue;
    query.set(key, String(value).trim());
  }
  return query.toString();
}

/** The view's own URL parameters: only what differs from the defaults, so links stay short. */
export function viewQuery(state) {
  const query = new URLSearchParams();
  for (const [key, fallback] of Object.entries(TABLE_DEFAULTS)) {
    if (state[key] !== "" && state[key] != null && String(state[key]) !== String(fallback)) query.set(key, String(state[key]));
  }
  return query.toString();
}

/** What is wrong with the table's score range, or null: a bound that is not a number from 0
 * to 100 (the API's bounds), or a min score above the max score (no take could match; the API
 * would answer an empty page). `fields` are the filters to mark, `text` the message. */
export function scoreRangeProblem(state) {
  const bounds = { min_score: "min score", max_score: "max score" };
  const values = {};
  for (const [key, label] of Object.entries(bounds)) {
    const raw = String(state[key] ?? "").trim();
    if (raw === "") continue;
    const value = Number(raw);
    if (!Number.isFinite(value) || value < 0 || value > 100) return { fields: [key], text: `${label} must be a number from 0 to 100 (got "${raw}")` };
    values[key] = value;
  }
  if (values.min_score != null && values.max_score != null && values.min_score > values.max_score) {
    return { fields: ["min_score", "max_score"], text: `min score (${values.min_score}) is above max score (${values.max_score}): no take can match` };
  }
  return null;
}

/** Clicking a column header: the same column flips the order, a new one sorts ascending. Any
 * sort goes back to the first page. */
export function nextSort(state, column) {
  const order = state.sort === column && state.order === "asc" ? "desc" : "asc";
  return { ...state, sort: column, order, offset: 0 };
}

/** Paging: "1–25 of 60" and the offsets of the previous/next pages (null at either end). */
export function pageInfo(offset, limit, total) {
  const first = total === 0 ? 0 : offset + 1;
  const last = Math.min(total, offset + limit);
  return {
    text: `${first}–${last} of ${total}`,
    previous: offset > 0 ? Math.max(0, offset - limit) : null,
    next: offset + limit < total ? offset + limit : null,
  };
}

const percent = (v) => (v == null ? "–" : `${fmt(100 * v, 1)} %`);
const count = (v) => (v == null ? "–" : String(v));

/** A take's largest foot skate as its cell shows it, always with its unit (the column holds
 * takes of both units, so its header names none): in cm with its share of the body height
 * beside it when known (`share`, in %: "8.6 cm (5.2 % height)"), in its own unit otherwise
 * ("2.4 % height": a BVH stores no unit, so the feet check sizes it against the body height);
 * "–" when there is none (no skate found, the feet not checked, or a run made before the
 * figure). The column sorts by the share, the one measure of every take. */
export function skateSize(value, unit, share = null) {
  if (value == null || !Number.isFinite(Number(value))) return "–";
  const number = `${fmt(Number(value), 1)} ${unit || "cm"}`;
  const known = unit !== "% height" && share != null && Number.isFinite(Number(share));
  return known ? `${number} (${fmt(Number(share), 1)} % height)` : number;
}

/** The take table's summary columns: the server's sort key, a header, a formatter, whether a
 * narrow window hides it, and whether its text (a name of any length) may break anywhere, so
 * the table fits its box from 1440 px. */
export const TAKE_COLUMNS = [
  { key: "name", label: "name", format: (v) => v },
  { key: "status", label: "run", format: (v) => v || "none" },
  { key: "score", label: "score", format: (v) => fmt(v, 1) },
  { key: "n_frames", label: "frames", format: count },
  { key: "duration_s", label: "duration", format: (v) => (v == null ? "–" : `${fmt(v, 1)} s`), narrow: true },
  { key: "rig", label: "rig", format: (v) => v || "–", narrow: true },
  { key: "twist_intervals", label: "twist", format: count },
  { key: "limb_spins", label: "spins", format: count, narrow: true, title: "limb spins and flips reported (never corrected)" },
  { key: "violation_share", label: "outside limits", format: percent },
  { key: "worst_joint", label: "worst joint", format: (v) => v || "–", narrow: true, wraps: true },
  { key: "filter_residual_mm", label: "filter mm", format: (v) => fmt(v, 2), narrow: true },
  { key: "missing_share", label: "missing", format: percent, narrow: true },
  { key: "n_findings", label: "findings", format: count },
  { key: "foot_skates", label: "skates", format: count, title: "foot skate findings: a planted foot sliding (– when the feet were not checked)" },
  { key: "foot_worst_skate", label: "worst skate", format: (v, row) => skateSize(v, row.foot_skate_unit, row.foot_worst_skate_pct),
    title: "the largest foot skate, each with its unit: in cm with its % of the body height beside it; in % of the body height alone when the take's unit does not convert to cm (a BVH stores none). Sorted by the % of the body height, the same measure in every take" },
  { key: "foot_penetrations", label: "below floor", format: count, narrow: true, title: "floor penetration findings: a foot below the floor" },
  { key: "foot_floating", label: "floating", format: count, narrow: true, title: "floating findings: a still foot above the floor" },
  { key: "review_status", label: "review", format: (v) => (v || "unreviewed").replace("_", " ") },
  { key: "reviewer", label: "reviewer", format: (v) => v || "–", narrow: true },
];

/** One cell's text. */
export function formatCell(key, row) {
  // An analysed take without a score is one no check could read (its rig's roles were not
  // found): say so, rather than a dash that reads as "not yet".
  if (key === "score" && row.status === "done" && row.score == null) return "not checked";
  const column = TAKE_COLUMNS.find((c) => c.key === key);
  return column ? column.format(row[key], row) : String(row[key] ?? "–");
}

/** A QA score's colour: red at 0, amber at 50, green at 100 (HSL hue 0→120); grey when the
 * take has no score yet. */
export function scoreColor(score) {
  if (score == null || Number.isNaN(Number(score))) return "#9aa3ad";
  const clamped = Math.max(0, Math.min(100, Number(score)));
  return `hsl(${Math.round(1.2 * clamped)}, 65%, 40%)`;
}

/** Progress of a shoot's analysis: share of takes finished (done or failed) and a line of text. */
export function progressSummary(progress) {
  const counts = progress.status_counts || {};
  const finished = (counts.done || 0) + (counts.failed || 0);
  const total = progress.n_takes || 0;
  const parts = ["queued", "running", "done", "failed"].filter((s) => counts[s]).map((s) => `${counts[s]} ${s}`);
  return {
    finished, total, share: total ? finished / total : 1,
    text: `${finished} of ${total} takes analysed${parts.length ? ` (${parts.join(", ")})` : ""} · ${progress.frames_done} frames`,
  };
}

/** An import's answer in three lists of lines: kept, skipped (with reason), failed (with error). */
export function importLines(result) {
  return {
    kept: (result.created || []).map((c) => (c.duplicate_of ? `${c.name} (same content as ${c.duplicate_of}, already in the shoot)` : c.name)),
    skipped: (result.skipped || []).map((s) => `${s.name}: ${s.reason}`),
    failed: (result.failed || []).map((f) => `${f.name}: ${f.error}`),
  };
}

/** Review queue keys: the decision a key records (case-insensitive), or null. */
export const REVIEW_KEYS = { a: "approved", f: "needs_fix", r: "rejected" };
export function decisionForKey(key) {
  return REVIEW_KEYS[String(key).toLowerCase()] || null;
}

/** The heat map's rows: the server sends `values` as joints × takes (shares in [0, 1]); the
 * chart draws one row per take, so this turns it into takes × joints, in percent (null kept
 * where the limits check did not run). */
export function heatmapRows(data) {
  return data.takes.map((_, t) => data.joints.map((_, j) => {
    const share = data.values[j][t];
    return share == null ? null : 100 * share;
  }));
}

/** Which of a shoot's controls the caller may use, from GET /me (`can`, `user_id`) and the
 * shoot's `owner_id` (the API's rule: its owner or an admin): renaming needs "upload" and
 * deleting (the shoot and all its takes) "delete_own", each on a shoot the caller owns, or
 * "delete_any" (an admin) on any shoot. No `me` (it failed): neither. The API refuses the
 * others with 403 anyway. */
export function shootControls(me, shoot) {
  const can = new Set((me && me.can) || []);
  const owns = shoot.owner_id != null && me != null && me.user_id != null && shoot.owner_id === me.user_id;
  const admin = can.has("delete_any");
  return { rename: can.has("upload") && (admin || owns), delete: admin || (can.has("delete_own") && owns) };
}

/** Whether the name typed to confirm a deletion is the shoot's: exactly (the API compares
 * the `confirm` parameter with the name as stored, spaces and case included). */
export function deleteConfirmed(typed, name) {
  return typeof typed === "string" && typed.length > 0 && typed === name;
}

/** Heat map page sizes offered, and the API's largest (GET /shoots/{id}/heatmap `limit`). */
export const HEATMAP_SIZES = [100, 200, 500];
export const HEATMAP_MAX_TAKES = 1000;
const HEATMAP_ROW_PX = 22;

/** The heat map's paging state, made safe: a whole page size in [1, HEATMAP_MAX_TAKES], an
 * offset that is a multiple of it, ≥ 0, and (once the total is known) not past the last page. */
export function heatmapPage(offset, limit, total = null) {
  const size = Math.max(1, Math.min(HEATMAP_MAX_TAKES, Number.parseInt(limit, 10) || 200));
  let start = Math.max(0, Number.parseInt(offset, 10) || 0);
  start -= start % size;
  if (total != null && total > 0 && start >= total) start = Math.floor((total - 1) / size) * size;
  if (total === 0) start = 0;
  return { offset: start, limit: size };
}

/** The query string of GET /shoots/{id}/heatmap for a page: the take table's sort, order and
 * filters (`state`, as tableState gives it), the heat map's own page. */
export function heatmapQuery(page, state = TABLE_DEFAULTS) {
  const safe = heatmapPage(page.offset, page.limit);
  return takesQuery({ ...TABLE_DEFAULTS, ...state, limit: safe.limit, offset: safe.offset });
}

/** The query string of the summary export: the table's filters, sort and order (not its page),
 * so a download holds the takes the table lists, in its order. */
export function exportQuery(state) {
  const full = { ...TABLE_DEFAULTS, ...state };
  return takesQuery(Object.fromEntries(Object.entries(full).filter(([key]) => key !== "limit" && key !== "offset")));
}

/** Whether the table's state filters the takes (so an empty heat map says why). */
export function isFiltered(state) {
  return TABLE_FILTERS.some((key) => state[key] !== "" && state[key] != null);
}

/** Whether going from one table state to the next changes which takes the heat map shows
 * (filters, sort or order; not the table's own page). */
export function heatmapChanged(before, after) {
  return ["sort", "order", ...TABLE_FILTERS].some((key) => String(before[key] ?? "") !== String(after[key] ?? ""));
}

/** What the pager shows: "takes 201–230 of 230" and the offsets of the pages before and
 * after (null at either end). */
export function heatmapPager(page, total) {
  const info = pageInfo(page.offset, page.limit, total);
  return { ...info, text: `takes ${info.text}` };
}

/** Row labels of the heat map are at most this many characters, rank included: a long take
 * name would otherwise take the chart's width from its cells. */
export const HEATMAP_LABEL_CHARS = 40;
/** Every joint column gets at least this many pixels, so each joint's label has room; a page
 * of many joints then scrolls sideways inside the chart's box, never the page. */
export const HEATMAP_COLUMN_PX = 26;
const LABEL_CHAR_PX = 7; // about one character of Plotly's 12 px tick font
/** The joint labels' angle: -45° needs about 17 px a column, -90° would need a taller margin. */
export const HEATMAP_TICK_ANGLE = -45;

/** A text cut to at most `max` characters (code points), keeping its start and its end with an
 * ellipsis between: "take_very_long…_end.bvh" (a take's end often says which it is). */
export function middleEllipsis(text, max = HEATMAP_LABEL_CHARS) {
  const chars = Array.from(String(text ?? ""));
  const size = Math.max(1, Math.floor(max));
  if (chars.length <= size) return chars.join("");
  const head = Math.ceil((size - 1) / 2);
  const tail = size - 1 - head;
  return `${chars.slice(0, head).join("")}…${tail ? chars.slice(chars.length - tail).join("") : ""}`;
}

/** A name for a Plotly hover label: its characters as Plotly shows them (&, < and > as
 * entities, so a name is never read as markup) in lines of at most `width` characters joined
 * by <br> (a 240-character file name on one line is wider than the window and gets cut). */
export function hoverLines(text, width = 60) {
  const chars = Array.from(String(text ?? ""));
  const lines = [];
  for (let at = 0; at < chars.length; at += width) lines.push(chars.slice(at, at + width).join(""));
  const escape = (line) => line.replace(/&/g, "&amp;").replace(/</g, "&lt;").replace(/>/g, "&gt;");
  return lines.map(escape).join("<br>");
}

/** The heat map's colours, light yellow at 0 % to dark red at the page's largest share (Plotly's
 * YlOrRd turned round): the chart and the colour key above it use the same stops. */
export const HEATMAP_COLORSCALE = [
  [0, "rgb(255,255,204)"], [0.125, "rgb(255,237,160)"], [0.25, "rgb(254,217,118)"], [0.375, "rgb(254,178,76)"],
  [0.5, "rgb(253,141,60)"], [0.625, "rgb(252,78,42)"], [0.75, "rgb(227,26,28)"], [0.875, "rgb(189,0,38)"], [1, "rgb(128,0,38)"],
];

/** The colour key's CSS background: the heat map's colour scale from left (0 %) to right. */
export function heatmapKeyGradient(scale = HEATMAP_COLORSCALE) {
  return `linear-gradient(to right, ${scale.map(([at, colour]) => `${colour} ${Number((100 * at).toFixed(2))}%`).join(", ")})`;
}

/** The chart of one page: one row per take, labelled with its rank in the shoot (so takes
 * with the same name stay separate rows) and its name cut to HEATMAP_LABEL_CHARS
 * (middleEllipsis), the full "rank. name" in `text` for the hover (hoverLines); z in percent (heatmapRows)
 * and `zmax`, the largest share on the page (the colour key's end); every joint and every take
 * labelled (`xaxis` / `yaxis`: tick mode "array"; Plotly's automatic ticks skip categories
 * when they are crowded), with fixed ranges (the first take on top); the margins the labels need (joints above and below the cells); a
 * height that gives every row the same number of pixels whatever the page size, and
 * `minWidth`: the width at which every joint column has HEATMAP_COLUMN_PX. */
export function heatmapFigure(data, offset) {
  const names = data.takes.map((t, k) => `${offset + k + 1}. ${t.name}`);
  const labels = data.takes.map((t, k) => {
    const rank = `${offset + k + 1}. `;
    return rank + middleEllipsis(t.name, Math.max(8, HEATMAP_LABEL_CHARS - rank.length));
  });
  const z = heatmapRows(data);
  const zmax = Math.max(0, ...z.flat().filter((v) => v != null));
  const longest = Math.max(0, ...labels.map((l) => Array.from(l).length));
  const longestJoint = Math.max(0, ...data.joints.map((j) => Array.from(String(j)).length));
  // The joints are labelled above and below the cells (a tall page scrolls in its box, and
  // one of the two is in view at either end), each at HEATMAP_TICK_ANGLE.
  const jointRoom = Math.round(30 + Math.abs(Math.sin((HEATMAP_TICK_ANGLE * Math.PI) / 180)) * LABEL_CHAR_PX * longestJoint);
  const margin = { l: 12 + LABEL_CHAR_PX * longest, r: 20, t: jointRoom, b: jointRoom };
  return {
    x: data.joints,
    y: labels,
    z,
    zmax: zmax > 0 ? zmax : 1,
    text: names.map((name) => { const hover = hoverLines(name); return data.joints.map(() => hover); }),
    // Fixed ranges, the first take on top: the invisible trace that gives the joints' top axis
    // its categories would otherwise pad an automatic range by 5 % (250 px on a 230-take page).
    xaxis: { tickmode: "array", tickvals: [...data.joints], ticktext: [...data.joints], range: [-0.5, data.joints.length - 0.5] },
    yaxis: { tickmode: "array", tickvals: [...labels], ticktext: [...labels], range: [data.takes.length - 0.5, -0.5] },
    margin,
    minWidth: margin.l + margin.r + HEATMAP_COLUMN_PX * data.joints.length,
    height: Math.max(260, margin.t + margin.b + HEATMAP_ROW_PX * data.takes.length),
  };
}
