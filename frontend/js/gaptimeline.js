// The per-marker gap timeline under the time bar of a marker take: one row per marker with
// gaps, one bar per gap, filled gaps (written by the run's fill) outlined, gaps left missing
// solid. A click on a bar jumps to the gap's first frame. `gapRows` is pure (unit-tested).
import { h } from "./dom.js";
import { spanOf } from "./timebar.js";

/** Colours of the marker step's findings (the time bar's marks, the gap bars). */
export const MARKER_COLORS = {
  gap: "#16a085",
  "gap not filled": "#c0392b",
  swap: "#8e44ad",
  spike: "#d35400",
  "static marker": "#7f8c8d",
  "absent marker": "#7f8c8d",
  "unlabelled marker": "#7f8c8d",
  "duplicate label": "#7f8c8d",
};

const GAP_KINDS = new Set(["gap", "gap not filled"]);

/**
 * The rows of the gap timeline from a run's findings.
 *
 * @param findings  the run's findings; those of kind "gap" (filled) and "gap not filled" are drawn
 * @param nFrames   frames in the take
 * @param order     marker names in the take's order (rows follow it; markers not in it go last)
 * @returns [{marker, filled, missing, bars: [{start, end, left, width, filled, label}]}]: one row
 *   per marker with a gap, bars by start frame, `left` and `width` in % of the row; `filled` and
 *   `missing` count the row's frames of each
 */
export function gapRows(findings, nFrames, order = []) {
  const rank = new Map(order.map((name, k) => [name, k]));
  const rows = new Map();
  for (const f of findings) {
    if (!GAP_KINDS.has(f.kind)) continue;
    if (!rows.has(f.joint)) rows.set(f.joint, { marker: f.joint, filled: 0, missing: 0, bars: [] });
    const row = rows.get(f.joint);
    const filled = f.kind === "gap";
    const [left, width] = spanOf(f.start_frame, f.end_frame, nFrames);
    const frames = f.end_frame - f.start_frame + 1;
    if (filled) row.filled += frames; else row.missing += frames;
    const error = f.value == null ? "no method could fill it" : `expected error ${f.value} ${f.unit}${f.method ? ` (${f.method})` : ""}`;
    row.bars.push({ start: f.start_frame, end: f.end_frame, left, width, filled, label: `${f.joint} · ${filled ? "filled" : "not filled"} · frames ${f.start_frame}–${f.end_frame} · ${error}` });
  }
  const key = (name) => (rank.has(name) ? rank.get(name) : Infinity);
  return [...rows.values()]
    .map((row) => ({ ...row, bars: row.bars.sort((a, b) => a.start - b.start) }))
    .sort((a, b) => key(a.marker) - key(b.marker) || (a.marker < b.marker ? -1 : a.marker > b.marker ? 1 : 0));
}

/**
 * The gap timeline's element: a labelled row per marker with gaps, and its frame cursor.
 *
 * @param rows    gapRows(…)
 * @param nFrames frames in the take
 * @param onJump  called with a clicked gap's first frame
 */
export function createGapTimeline(rows, nFrames, onJump) {
  const cursors = [];
  const rowEl = (row) => {
    const track = h("div", { class: "gt-track" }, row.bars.map((bar) => {
      const el = h("div", { class: `gt-bar ${bar.filled ? "gt-filled" : "gt-missing"}`, title: bar.label, "data-start": bar.start, "data-end": bar.end });
      el.style.left = `${bar.left}%`;
      el.style.width = `${bar.width}%`;
      el.addEventListener("click", () => onJump(bar.start));
      return el;
    }));
    const cursor = h("div", { class: "gt-cursor" });
    cursors.push(cursor);
    track.append(cursor);
    return h("div", { class: "gt-row", "data-marker": row.marker }, h("span", { class: "gt-name", title: row.marker }, row.marker), track);
  };
  const legend = h("p", { class: "muted gt-legend" }, h("span", { class: "gt-key gt-filled" }), " filled by the run · ",
    h("span", { class: "gt-key gt-missing" }), " gap not filled · click a gap to go to it");
  const el = h("div", { class: "gap-timeline", id: "gap-timeline", role: "group", "aria-label": "gaps per marker" }, rows.map(rowEl), legend);
  return {
    el,
    setFrame(f) { for (const c of cursors) c.style.left = `${(100 * (f + 0.5)) / Math.max(1, nFrames)}%`; },
  };
}
