// The foot contact timeline under the time bar of a take the feet step checked: two rows (left
// and right foot), one bar per contact, the feet findings (skate, penetration, floating, jitter)
// marked over them, and under each row the foot locks of its skate findings, drawn by their
// newest decision (lock-events.js keeps them in step with the findings table). A click on a bar
// or a mark jumps to its first frame; so does Enter or Space on a focused one: the timeline is
// one Tab stop, the arrow keys move between its bars and marks (left/right in time along a
// foot's row, up/down to the other foot, Home/End to a row's ends). `contactRows`, `lockMarks`,
// `lockStyle` and `stopAfter` are pure (unit-tested).
import { h } from "./dom.js";
import { onLockDecisions } from "./lock-events.js";
import { spanOf } from "./timebar.js";

/** Colours of the feet step's findings (the time bar's marks, the contact timeline's marks). */
export const FEET_COLORS = {
  skate: "#c0392b",
  penetration: "#8e44ad",
  floating: "#2980b9",
  jitter: "#d35400",
};

const FEET = ["left", "right"];

/** What each decision of a foot lock means for the reviewed download, as its mark's title says. */
const LOCK_STATES = {
  accept: "accepted: the reviewed download locks it",
  reject: "rejected: left as recorded",
  undecided: "undecided: left as recorded",
  followed: "undecided: locked in the run's corrected take (its feet_apply), and in the reviewed take unless rejected",
};
const LOCK_COLOR = "#1e8449"; // an accepted lock: solid; a rejected one: hatched and dim

/**
 * The inline style of a foot lock's mark by its newest decision: an accepted lock solid, a
 * rejected one hatched and dim, an undecided one an outline, striped when the run locked it
 * (its feet_apply choice: the reviewed download follows the run).
 *
 * @param decision  "accept", "reject", or null / undefined for undecided
 * @param runLocked whether the run locked it
 * @returns {{background: string, border: string, opacity: string}} CSS values
 */
export function lockStyle(decision, runLocked = false) {
  if (decision === "accept") return { background: LOCK_COLOR, border: `1px solid ${LOCK_COLOR}`, opacity: "1" };
  if (decision === "reject") return { background: "repeating-linear-gradient(135deg, #95a5a6 0 2px, transparent 2px 5px)", border: "1px dashed #95a5a6", opacity: "0.6" };
  if (runLocked) return { background: `repeating-linear-gradient(90deg, ${LOCK_COLOR} 0 3px, transparent 3px 5px)`, border: `1px solid ${LOCK_COLOR}`, opacity: "1" };
  return { background: "transparent", border: `1px solid ${LOCK_COLOR}`, opacity: "1" };
}

/** The contact of `foot` that frames `start`–`end` overlap most (the first of equals), or undefined. */
export function overlappedMost(contacts, foot, start, end) {
  let best, most = 0;
  for (const c of contacts) {
    const shared = Math.min(c.end, end) - Math.max(c.start, start) + 1;
    if (c.foot === foot && shared > most) { best = c; most = shared; }
  }
  return best;
}

/**
 * The foot locks of a foot's row: one per skate finding with an id, over the frames the lock
 * holds the foot (as `mocapqa feet fix` chooses them: the contact of that foot the finding
 * overlaps most, the first of equals, else the finding's own frames).
 *
 * @param contacts  the run's `series.feet.contacts`: [{foot, start, end}], frames inclusive
 * @param findings  the run's findings; the skate ones with a string `id` have a lock
 * @param foot      "left" or "right"
 * @param nFrames   frames in the take
 * @param decisions lock id -> "accept" | "reject" (newest; absent ids are undecided)
 * @returns [{id, foot, start, end, left, width, runLocked, decision, style, label}] by start frame; `left`,
 *   `width` in % of the row, `decision` "accept" | "reject" | "undecided", `style` lockStyle(…)
 */
export function lockMarks(contacts, findings, foot, nFrames, decisions = {}) {
  return findings.filter((f) => f.kind === "skate" && f.foot === foot && typeof f.id === "string" && f.id)
    .map((f) => {
      const contact = overlappedMost(contacts, foot, f.start_frame, f.end_frame);
      const [start, end] = contact ? [contact.start, contact.end] : [f.start_frame, f.end_frame];
      const [left, width] = spanOf(start, end, nFrames);
      return decidedLock({ id: f.id, foot, start, end, left, width, runLocked: f.applied === true }, decisions[f.id]);
    })
    .sort((a, b) => a.start - b.start);
}

/**
 * A lock mark (lockMarks) drawn by `decision`: its `decision`, `style` and `label` set.
 *
 * @param lock     {id, foot, start, end, left, width, runLocked, …} (`runLocked`: the run locked it)
 * @param decision "accept", "reject", or null / undefined for undecided
 */
export function decidedLock(lock, decision) {
  const state = decision === "accept" || decision === "reject" ? decision : "undecided";
  const meaning = state === "undecided" && lock.runLocked ? "followed" : state;
  return { ...lock, decision: state, style: lockStyle(decision, Boolean(lock.runLocked)),
    label: `${lock.foot} foot lock · frames ${lock.start}–${lock.end} · ${LOCK_STATES[meaning]}` };
}

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
    return { foot, contacts: bars.length, findings: marks.length, bars, marks, locks: lockMarks(contacts, findings, foot, nFrames) };
  });
}

/** Give a lock's mark the look and title of its decision. */
function styleLock(el, lock) {
  Object.assign(el.style, lock.style);
  el.dataset.decision = lock.decision;
  el.title = lock.label;
  el.setAttribute("aria-label", lock.label);
}

/** The legend's keys of the foot locks (only when the take has any). */
function lockLegend(runLocked = false) {
  const keys = [["accept", false, "accepted"], ["reject", false, "rejected"], [null, false, "undecided"]];
  if (runLocked) keys.push([null, true, "undecided, locked by the run"]);
  return keys.flatMap(([d, run, name]) => {
    const key = h("span", { class: "ct-key" });
    Object.assign(key.style, lockStyle(d, run), { height: "5px" });
    return [key, ` lock ${name} `];
  });
}

/** Keys that move between the timeline's stops (stopAfter). */
const MOVES = new Set(["ArrowLeft", "ArrowRight", "ArrowUp", "ArrowDown", "Home", "End"]);

/**
 * The stop a key moves to in the contact timeline: along a row (ArrowLeft/ArrowRight one step,
 * Home/End its ends, staying at either end) or to the next row with stops up or down (ArrowUp /
 * ArrowDown, on the stop starting nearest the current one's start, the first of equals).
 *
 * @param rows  each row's stops' first frames, in the order the row walks them
 * @param at    the current stop, [row, index]
 * @param key   the key pressed
 * @returns [row, index] (`at` itself when there is nowhere to go), or null for another key
 */
export function stopAfter(rows, [row, index], key) {
  const last = rows[row].length - 1;
  if (key === "ArrowRight") return [row, Math.min(last, index + 1)];
  if (key === "ArrowLeft") return [row, Math.max(0, index - 1)];
  if (key === "Home") return [row, 0];
  if (key === "End") return [row, last];
  if (key !== "ArrowUp" && key !== "ArrowDown") return null;
  const step = key === "ArrowDown" ? 1 : -1;
  let other = row + step;
  while (other >= 0 && other < rows.length && !rows[other].length) other += step;
  if (other < 0 || other >= rows.length) return [row, index];
  const from = rows[row][index];
  let best = 0;
  rows[other].forEach((start, k) => { if (Math.abs(start - from) < Math.abs(rows[other][best] - from)) best = k; });
  return [other, best];
}

/** Make the timeline's bars and marks (each row's `stops`, in walking order) one Tab stop that
 * the arrow keys walk (stopAfter); Enter or Space does what a click does. */
function keyboardStops(el, stops) {
  const all = stops.flat();
  all.forEach((stop, k) => stop.setAttribute("tabindex", k === 0 ? "0" : "-1"));
  const where = (target) => {
    for (let r = 0; r < stops.length; r++) { const k = stops[r].indexOf(target); if (k >= 0) return [r, k]; }
    return null;
  };
  // The stop last reached keeps the Tab stop: Tab back in lands where the reviewer left.
  el.addEventListener("focusin", (e) => {
    if (!where(e.target)) return;
    for (const stop of all) stop.setAttribute("tabindex", stop === e.target ? "0" : "-1");
    // Drawn over its neighbours, ringed: a thin mark's own focus ring would hide under them.
    Object.assign(e.target.style, { outline: "2px solid #1a5276", outlineOffset: "1px", zIndex: "3" });
  });
  el.addEventListener("focusout", (e) => { if (where(e.target)) Object.assign(e.target.style, { outline: "", outlineOffset: "", zIndex: "" }); });
  el.addEventListener("keydown", (e) => {
    const at = where(e.target);
    if (!at || e.ctrlKey || e.metaKey || e.altKey) return;
    if (e.key === "Enter" || e.key === " ") { e.preventDefault(); e.stopPropagation(); e.target.click(); return; }
    if (!MOVES.has(e.key)) return;
    e.preventDefault(); e.stopPropagation(); // not the take view's frame steps
    const [r, k] = stopAfter(stops.map((row) => row.map((stop) => Number(stop.dataset.start))), at, e.key);
    stops[r][k].focus();
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
  const stops = []; // each row's bars and marks, in walking order
  const locks = new Map(); // lock id -> [its mark, its data]
  const place = (el, item) => {
    el.style.left = `${item.left}%`;
    el.style.width = `${item.width}%`;
    el.setAttribute("role", "button");
    if (item.label) el.setAttribute("aria-label", item.label);
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
    const lockEls = (row.locks || []).map((lock) => {
      const el = place(h("div", { class: "ct-lock", "data-lock": lock.id, "data-start": lock.start, "data-end": lock.end }), lock);
      Object.assign(el.style, { position: "absolute", top: "0", bottom: "0", minWidth: "3px", boxSizing: "border-box", cursor: "pointer" });
      styleLock(el, lock);
      locks.set(lock.id, [el, lock]);
      return el;
    });
    const lane = lockEls.length ? h("div", { class: "ct-locks", "aria-label": `${row.foot} foot locks` }, lockEls) : "";
    if (lane) Object.assign(lane.style, { position: "relative", height: "6px", marginTop: "1px" });
    // In time order; at one frame a contact, then its findings, then its lock.
    const order = (x) => (x.classList.contains("ct-bar") ? 0 : x.classList.contains("ct-mark") ? 1 : 2);
    stops.push([...bars, ...marks, ...lockEls].sort((x, y) => Number(x.dataset.start) - Number(y.dataset.start) || order(x) - order(y)));
    return h("div", { class: "ct-row", "data-foot": row.foot }, h("span", { class: "ct-name" }, `${row.foot} foot`), track, lane);
  };
  const legend = h("p", { class: "muted ct-legend" }, h("span", { class: "ct-key ct-bar-key" }), " contact (foot planted) · ",
    Object.entries(FEET_COLORS).flatMap(([kind, color]) => {
      const key = h("span", { class: "ct-key" });
      key.style.background = color;
      return [key, ` ${kind} `];
    }), "· click one to go to it (keyboard: arrow keys move between them, Enter goes)");
  const el = h("div", { class: "contact-timeline", id: "contact-timeline", role: "group", "aria-label": "foot contacts: arrow keys move between contacts, findings and foot locks, Enter goes to one" }, rows.map(rowEl), legend);
  keyboardStops(el, stops.filter((row) => row.length));
  if (locks.size) legend.append(h("br"), ...lockLegend([...locks.values()].some(([, lock]) => lock.runLocked)));
  /** Draw each lock by its newest decision (lock id -> "accept" | "reject"; absent: undecided). */
  const setLockDecisions = (decisions) => {
    for (const [id, [mark, lock]] of locks) styleLock(mark, decidedLock(lock, decisions[id]));
  };
  // Until the timeline leaves the page (another take or run opened).
  const stop = locks.size ? onLockDecisions((detail) => { if (el.isConnected) setLockDecisions(detail.decisions); else stop(); }) : () => {};
  return {
    el,
    setFrame(f) { for (const c of cursors) c.style.left = `${(100 * (f + 0.5)) / Math.max(1, nFrames)}%`; },
    setLockDecisions,
  };
}
