// The foot contact timeline under the time bar of a take the feet step checked: two rows (left
// and right foot), one bar per contact, the feet findings (skate, penetration, floating, jitter)
// marked over them. A click on a bar or a mark jumps to its first frame. `contactRows` is pure
// (unit-tested).
import { h } from "./dom.js";
import { spanOf } from "./timebar.js";

/** Colours of the feet step's findings (the time bar's marks, the contact timeline's marks). */
export const FEET_COLORS = {
  skate: "#c0392b",
  penetration: "#8e44ad",
  floating: "#2980b9",
  jitter: "#d35400",
};

const FEET = ["left", "right"];

/**
 * The rows of the contact timeline.
 *
 * @param contacts  the run's `series.feet.contacts`: [{foot, start, end, confidence}], frames inclusive
 * @param findings  the run's findings; those with a `foot` and a kind of FEET_COLORS are marked
 * @param nFrames   frames in the take
 * @returns [{foot, contacts, findings, bars: [{start, end, left, width, label}],
 *   marks: [{kind, start, end, left, width, color, label}]}]: always two rows, left then right,
 *   bars and marks by start frame, `left` and `width` in % of the row
 */
export function contactRows(contacts, findings, nFrames) {
  return FEET.map((foot) => {
    const bars = contacts.filter((c) => c.foot === foot)
      .map((c) => {
        const [left, width] = spanOf(c.start, c.end, nFrames);
        const confidence = c.confidence == null ? "" : ` · confidence ${c.confidence.toFixed(2)}`;
        return { start: c.start, end: c.end, left, width, label: `${foot} foot · contact · frames ${c.start}–${c.end}${confidence}` };
      })
      .sort((a, b) => a.start - b.start);
    const marks = findings.filter((f) => f.foot === foot && f.kind in FEET_COLORS)
      .map((f) => {
        const [left, width] = spanOf(f.start_frame, f.end_frame, nFrames);
        const size = f.value == null ? "" : ` · ${f.value} ${f.unit}`;
        return { kind: f.kind, start: f.start_frame, end: f.end_frame, left, width, color: FEET_COLORS[f.kind], label: `${foot} foot · ${f.kind} · frames ${f.start_frame}–${f.end_frame}${size}` };
      })
      .sort((a, b) => a.start - b.start);
    return { foot, contacts: bars.length, findings: marks.length, bars, marks };
  });
}

/**
 * The contact timeline's element: a labelled row per foot, and its frame cursor.
 *
 * @param rows    contactRows(…)
 * @param nFrames frames in the take
 * @param onJump  called with a clicked contact's or finding's first frame
 */
export function createContactTimeline(rows, nFrames, onJump) {
  const cursors = [];
  const place = (el, item) => {
    el.style.left = `${item.left}%`;
    el.style.width = `${item.width}%`;
    el.addEventListener("click", () => onJump(item.start));
    return el;
  };
  const rowEl = (row) => {
    const bars = row.bars.map((bar) => place(h("div", { class: "ct-bar", title: bar.label, "data-start": bar.start, "data-end": bar.end }), bar));
    const marks = row.marks.map((mark) => {
      const el = place(h("div", { class: "ct-mark", title: mark.label, "data-kind": mark.kind, "data-start": mark.start, "data-end": mark.end }), mark);
      el.style.background = mark.color;
      return el;
    });
    const cursor = h("div", { class: "ct-cursor" });
    cursors.push(cursor);
    const track = h("div", { class: "ct-track" }, bars, marks, cursor);
    return h("div", { class: "ct-row", "data-foot": row.foot }, h("span", { class: "ct-name" }, `${row.foot} foot`), track);
  };
  const legend = h("p", { class: "muted ct-legend" }, h("span", { class: "ct-key ct-bar-key" }), " contact (foot planted) · ",
    Object.entries(FEET_COLORS).flatMap(([kind, color]) => {
      const key = h("span", { class: "ct-key" });
      key.style.background = color;
      return [key, ` ${kind} `];
    }), "· click to go to it");
  const el = h("div", { class: "contact-timeline", id: "contact-timeline", role: "group", "aria-label": "foot contacts" }, rows.map(rowEl), legend);
  return {
    el,
    setFrame(f) { for (const c of cursors) c.style.left = `${(100 * (f + 0.5)) / Math.max(1, nFrames)}%`; },
  };
}
