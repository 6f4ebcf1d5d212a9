// Pure functions of the take view: finding colours and time-bar marks, the frame drawn at a
// frame number, the labels and link of the player, and the keyboard's commands. No DOM:
// unit-tested with node --test.
import { SPIN_COLOR } from "./charts.js";
import { DECISION_KEYS } from "./decisions.js";
import { flaggedAt } from "./findings.js";
import { sampleOf } from "./frames.js";
import { fmt, seconds } from "./format.js";
import { MARKER_COLORS } from "./gaptimeline.js";

export const OVERVIEW_FRAMES = 800; // frames of a take drawn before any window is loaded
export const LIMITS_COLOR = "#e67e22";
export const LOOP_MARGIN_S = 0.5; // "loop this finding": seconds shown before and after it
const REVIEW_KEYS = { a: "approved", f: "needs_fix", r: "rejected" };
const ITEM_KEYS = new Set(Object.keys(DECISION_KEYS)); // accept / reject a twist interval or swap

// Drawn and coloured in this order, so a twist interval shows over a spin over a long limits
// run (on the time bar and on a joint flagged by several).
const KIND_ORDER = { limits: 0, spin: 1, twist: 2 };
export const byKind = (a, b) => (KIND_ORDER[a.kind] ?? 0) - (KIND_ORDER[b.kind] ?? 0);

/** A finding's colour: its chain's for a twist interval (`chainColor`: joint → colour), the
 * spin colour, the marker step's kinds' colours, else the limits colour. */
export function findingColors(chainColor) {
  return (f) => (f.kind === "twist" ? chainColor.get(f.joint) || "#c0392b" : f.kind === "spin" ? SPIN_COLOR : MARKER_COLORS[f.kind] || LIMITS_COLOR);
}

/** The time bar's marks of `findings`, drawn in kind order (byKind). */
export function timeMarks(findings, colorOf) {
  return [...findings].sort(byKind).map((f) => ({ start: f.start_frame, end: f.end_frame, color: colorOf(f), label: `${f.kind} · ${f.joint} · ${f.start_frame}–${f.end_frame}` }));
}

/** The one-line description of a take under its name. */
export function takeLine(take) {
  return `${take.format.toUpperCase()} · ${take.n_frames} frames at ${fmt(take.fps, 2)} fps · ${take.n_joints} ${take.kind === "motion" ? "joints" : "keypoints"} · sha256 ${take.sha256.slice(0, 12)}…`;
}

/** The legend of the 3D views: what the bones, colours and marks mean for this kind of take. */
export function viewLegend(oriented, markersRan) {
  if (oriented) return "bones are drawn in their parent joint's frame; the orange side marks the roll";
  return markersRan ? "markers; sticks join the segments inferred from the take; hollow green: filled by a gap fill (outlined on the gap timeline); purple: bridged by the filter"
    : "keypoints fade with their detection confidence; purple: bridged by the filter (hatched on the time bar)";
}

/** Steps no check could read the take for (no roles, no model), as [name, step] pairs. */
export const uncheckedSteps = (steps) => Object.entries(steps).filter(([, st]) => st.state === "no_roles" || st.state === "no_model");

/** The frame `f` clamped to the take's frames and rounded. */
export const clampFrame = (f, nFrames) => Math.max(0, Math.min(nFrames - 1, Math.round(f)));

/**
 * What the views draw at frame `f`: from the full-rate `detail` window when it holds `f`, else
 * from the (decimated) `overview`.
 *
 * @param take {oriented, intervals, jointIndex, colorOf, selected}: the findings on drawn joints
 *   in kind order, joint name → index, the findings' colour, the selected joint's index
 */
export function frameAt(detail, overview, f, take) {
  const source = detail && f >= detail.frames[0] && f <= detail.frames[detail.frames.length - 1] ? detail : overview;
  const k = sampleOf(source, f);
  const { oriented } = take;
  return {
    shown: source.frames[k], raw: source.raw[k], corrected: source.corrected[k],
    rawRotations: oriented ? source.raw_rotations[k] : null, correctedRotations: oriented ? source.corrected_rotations[k] : null,
    flagged: flaggedAt(take.intervals, take.jointIndex, f, take.colorOf), selected: take.selected,
    confidence: source.confidence ? source.confidence[k] : null, bridged: source.bridged ? source.bridged[k] : null,
    filled: source.filled ? source.filled[k] : null,
  };
}

/** The player's frame line: the frame, its time and how many joints are flagged. */
export const frameText = (f, nFrames, fps, flagged) => `frame ${f} / ${nFrames - 1} · ${seconds(f, fps)} · ${flagged} flagged joint(s)`;

/** The in/out line: the range, its length and whether playback loops over it. */
export function loopText(range, looping) {
  return range ? `in ${range[0]} · out ${range[1]} (${range[1] - range[0] + 1} frames)${looping ? " · looping" : ""}` : "in/out: none (I / O or drag on the bar)";
}

/** The take view's link parameters: the run, the frame, the selected joint, the in/out range
 * and the findings filter's parameters (filterParams). */
export function takeQuery(runId, state, filterQuery) {
  const query = new URLSearchParams({ run: runId, frame: state.frame });
  if (state.joint) query.set("joint", state.joint);
  if (state.loop) query.set("loop", state.loop.join("-"));
  for (const [name, value] of Object.entries(filterQuery)) query.set(name, value);
  return query;
}

/**
 * The take view's command for a key press (modifier keys other than shift excluded by the
 * caller), or null:
 * play (space), step (arrows; `by` frames, 10 with shift), walk (N/P; `dir` ±1), in, out (I/O),
 * loop-finding (shift+L), loop (l), close (C), item (Y/X: decisions.js decides), review (A/F/R;
 * `decision`), help (?).
 */
export function keyCommand(key, shiftKey) {
  const lower = key.toLowerCase();
  if (key === " ") return { name: "play" };
  if (key === "ArrowRight" || key === "ArrowLeft") return { name: "step", by: (key === "ArrowRight" ? 1 : -1) * (shiftKey ? 10 : 1) };
  if (lower === "n" || lower === "p") return { name: "walk", dir: lower === "n" ? 1 : -1 };
  if (lower === "i") return { name: "in" };
  if (lower === "o") return { name: "out" };
  if (key === "L" && shiftKey) return { name: "loop-finding" };
  if (key === "l") return { name: "loop" };
  if (lower === "c") return { name: "close" };
  if (ITEM_KEYS.has(lower)) return { name: "item" };
  if (REVIEW_KEYS[lower]) return { name: "review", decision: REVIEW_KEYS[lower] };
  if (key === "?") return { name: "help" };
  return null;
}
