// The time bar under the player: the whole take from left to right, with the findings as
// coloured marks, bridged gaps hatched, the loop range (in/out) as a band with two handles, and
// the current frame. A click jumps to its frame; a drag sets the loop range; a handle's drag moves
// that end. The pure helpers below are unit-tested.
import { h } from "./dom.js";

/** The frame under `x` pixels from the bar's left edge, `width` pixels wide, clamped. */
export function frameAtX(x, width, nFrames) {
  if (width <= 0 || nFrames <= 1) return 0;
  return Math.max(0, Math.min(nFrames - 1, Math.round((x / width) * (nFrames - 1))));
}

/** Left edge and width of frames a..b (both drawn) in % of the bar. */
export function spanOf(a, b, nFrames) {
  const n = Math.max(1, nFrames);
  return [(100 * Math.min(a, b)) / n, (100 * (Math.abs(b - a) + 1)) / n];
}

/** The range after setting its in point at `frame` (its out point kept when after, else the end). */
export const withIn = (range, frame, nFrames) => [frame, range && range[1] >= frame ? range[1] : nFrames - 1];

/** The range after setting its out point at `frame` (its in point kept when before, else 0). */
export const withOut = (range, frame) => [range && range[0] <= frame ? range[0] : 0, frame];

/** An in/out range from a link's "A-B" (frames inside the take, A ≤ B), else null. */
export function parseRange(text, nFrames) {
  const match = /^(\d+)-(\d+)$/.exec(String(text ?? ""));
  if (!match) return null;
  const [a, b] = [Number(match[1]), Number(match[2])];
  return a <= b && b < nFrames ? [a, b] : null;
}

/** Runs of consecutive frames where `flags[k]` is true, as [start, end] pairs of `frames[k]`. */
export function runsOf(frames, flags) {
  const runs = [];
  let start = null;
  flags.forEach((on, k) => {
    if (on && start === null) start = k;
    if ((!on || k === flags.length - 1) && start !== null) {
      runs.push([frames[start], frames[on ? k : k - 1]]);
      start = null;
    }
  });
  return runs;
}

/**
 * @param nFrames   frames in the take
 * @param marks     [{start, end, color, label}] drawn over the bar (findings)
 * @param onJump    called with a clicked frame
 * @param onRange   called with a dragged [in, out] range
 */
export function createTimebar({ nFrames, marks, onJump, onRange }) {
  const place = (el, a, b) => { const [left, width] = spanOf(a, b, nFrames); el.style.left = `${left}%`; el.style.width = `${width}%`; };
  const markOf = (m) => {
    const el = h("div", { class: "tb-mark", title: m.label });
    el.style.background = m.color;
    place(el, m.start, m.end);
    return el;
  };
  const markBox = h("div", { class: "tb-marks" }, marks.map(markOf));
  const gaps = h("div", { class: "tb-gaps" });
  const inHandle = h("span", { class: "tb-handle tb-in", title: "in point (I): drag to move" });
  const outHandle = h("span", { class: "tb-handle tb-out", title: "out point (O): drag to move" });
  const loop = h("div", { class: "tb-loop", id: "loop-band", hidden: true }, inHandle, outHandle);
  const cursor = h("div", { class: "tb-cursor" });
  // A slider to the keyboard and to screen readers: ←/→ step (the take view's keys), Home/End
  // go to the first/last frame, Page Up/Down move a tenth of the take.
  const bar = h("div", {
    class: "timebar", id: "timebar", title: "click: go to a frame · drag: set the loop range", tabindex: "0",
    role: "slider", "aria-label": "time bar", "aria-valuemin": "0", "aria-valuemax": String(Math.max(0, nFrames - 1)), "aria-valuenow": "0",
  }, markBox, gaps, loop, cursor);
  let now = 0;
  bar.addEventListener("keydown", (e) => {
    const step = Math.max(1, Math.round(nFrames / 10));
    const target = { Home: 0, End: nFrames - 1, PageUp: now - step, PageDown: now + step }[e.key];
    if (target === undefined) return;
    e.preventDefault();
    onJump(Math.max(0, Math.min(nFrames - 1, target)));
  });
  let range = null, drag = null;

  const frameOf = (e) => { const r = bar.getBoundingClientRect(); return frameAtX(e.clientX - r.left, r.width, nFrames); };
  bar.addEventListener("pointerdown", (e) => {
    if (e.button !== 0) return;
    e.preventDefault();
    bar.setPointerCapture(e.pointerId);
    const end = e.target === inHandle ? "in" : e.target === outHandle ? "out" : null;
    drag = { end, anchor: frameOf(e), x: e.clientX, moved: false };
  });
  bar.addEventListener("pointermove", (e) => {
    if (!drag) return;
    if (!drag.moved && Math.abs(e.clientX - drag.x) < 4) return;
    drag.moved = true;
    const f = frameOf(e);
    const next = drag.end === "in" ? [f, range[1]] : drag.end === "out" ? [range[0], f] : [drag.anchor, f];
    onRange([Math.min(...next), Math.max(...next)]);
  });
  bar.addEventListener("pointerup", (e) => {
    if (!drag) return;
    bar.releasePointerCapture(e.pointerId);
    if (!drag.moved && !drag.end) onJump(frameOf(e));
    drag = null;
  });

  return {
    el: bar,
    setFrame(f) {
      now = f;
      cursor.style.left = `${(100 * (f + 0.5)) / Math.max(1, nFrames)}%`;
      bar.setAttribute("aria-valuenow", String(f));
      bar.setAttribute("aria-valuetext", `frame ${f} of ${nFrames}`);
    },
    /** Show the loop range ([a, b] or null) and whether playback loops over it. */
    setRange(next, looping) {
      range = next;
      loop.hidden = !next;
      loop.classList.toggle("looping", Boolean(looping));
      if (next) place(loop, next[0], next[1]);
    },
    /** The findings marked: [{start, end, color, label}, …] (those the list's filters keep). */
    setMarks(next) { markBox.replaceChildren(...next.map(markOf)); },
    /** Bridged gaps: [[start, end], …] frames drawn hatched. */
    setGaps(runs) {
      gaps.replaceChildren(...runs.map(([a, b]) => { const el = h("div", { class: "tb-gap", title: `bridged gap: frames ${a}–${b}` }); place(el, a, b); return el; }));
    },
  };
}
