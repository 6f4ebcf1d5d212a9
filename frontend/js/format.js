// Pure formatting and ordering helpers shared by the views (no DOM).
import { optionDefaults } from "./run-options.js";

export const fmt = (v, digits = 1) => (v == null || Number.isNaN(v) ? "–" : Number(v).toFixed(digits));

/** Seconds shown with the precision one frame needs at `fps` (30 fps -> 2 decimals). */
export function seconds(frame, fps) {
  const digits = Math.min(3, Math.max(1, Math.ceil(Math.log10(Math.max(fps, 1)))));
  return `${(frame / fps).toFixed(digits)} s`;
}

/** Sort keys of the findings table: "value" sorts by magnitude (−77° is larger than +2°). */
export const FINDING_KEYS = {
  kind: (f) => f.kind,
  joint: (f) => f.joint,
  start_frame: (f) => f.start_frame,
  duration: (f) => f.end_frame - f.start_frame + 1,
  value: (f) => (f.value == null ? null : Math.abs(f.value)),
  confidence: (f) => f.confidence,
};

/** A sorted copy of `rows` by `key` (of `keys`: FINDING_KEYS, or others alike), `dir` 1
 * ascending or −1; missing last. */
export function sortFindings(rows, key, dir, keys = FINDING_KEYS) {
  const get = keys[key] || FINDING_KEYS.start_frame;
  return [...rows].sort((a, b) => {
    const x = get(a), y = get(b);
    if (x == null && y == null) return a.start_frame - b.start_frame;
    if (x == null) return 1;
    if (y == null) return -1;
    if (x < y) return -dir;
    if (x > y) return dir;
    return a.start_frame - b.start_frame;
  });
}

/** The steps of a run that actually ran ("twist+limits"), from its summary; options before. */
export function stepsRan(run) {
  const steps = run.summary && run.summary.steps;
  if (!steps) return run.status === "done" ? run.options.checks.join("+") : "";
  const ran = Object.entries(steps).filter(([, state]) => state === "done").map(([name]) => name);
  return ran.length ? ran.join("+") : "no step ran";
}

/** What tells two runs of a take apart in a list: the steps that ran, the twist choice and the
 * foot locks when they are not their defaults in `described` (GET /run-options), the filter
 * ("twist+limits · apply all · feet locked confident · quat-pd"). */
export function runOptionsLabel(run, described) {
  const parts = [stepsRan(run)];
  const apply = run.options && run.options.twist_apply;
  if (apply && apply !== optionDefaults(described).twist_apply) parts.push(`apply ${apply}`);
  // Foot locks only where the feet step ran: without it the choice locked nothing.
  const feet = run.options && run.options.feet_apply;
  const feetRan = run.summary && run.summary.steps ? run.summary.steps.feet === "done" : (run.options.checks || []).includes("feet");
  if (feet && feetRan && feet !== optionDefaults(described).feet_apply) parts.push(`feet locked ${feet}`);
  if (run.options && run.options.filter_method) parts.push(run.options.filter_method);
  return parts.filter(Boolean).join(" · ");
}

/** Which of GET /run-options' `take_checks` a take reads from: "motion", "markers" (a keypoint
 * take of one of its `marker_formats`: C3D, TRC) or "keypoints". */
export const takeChecksKind = (take, described) =>
  (take.kind === "motion" ? "motion" : (described.marker_formats || []).includes(take.format) ? "markers" : "keypoints");

/** Run checks a take can run, as the server says (`take_checks` of GET /run-options, from
 * pipeline/options.py): twist and limits need joint rotations, the marker checks markers. */
export const checksFor = (take, described) => described.take_checks[takeChecksKind(take, described)] || [];

/**
 * The finding N (dir 1) or P (dir −1) opens, or null at either end. The findings kept are walked
 * in time order (start frame, then their order in `findings`), one finding at a time: from the
 * `current` one while the player stands on its start (two findings starting on one frame are two
 * stops), else from `frame` (the next to start after it, or the last to start before it).
 */
export function nextFinding(findings, current, frame, dir) {
  const order = findings.map((f, k) => [f, k]).sort((a, b) => a[0].start_frame - b[0].start_frame || a[1] - b[1]).map(([f]) => f);
  const at = current && current.start_frame === frame ? order.indexOf(current) : -1;
  if (at >= 0) return order[at + dir] ?? null;
  if (dir > 0) return order.find((f) => f.start_frame > frame) ?? null;
  for (let k = order.length - 1; k >= 0; k--) if (order[k].start_frame < frame) return order[k];
  return null;
}

/** One colour per chain/joint name, stable for a given order of names. */
export const PALETTE = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"];
export const colorOf = (names) => new Map(names.map((n, k) => [n, PALETTE[k % PALETTE.length]]));

/** Whether two findings are the same: same kind and joint, overlapping frames. */
const sameFinding = (a, b) => a.kind === b.kind && a.joint === b.joint && a.start_frame <= b.end_frame && b.start_frame <= a.end_frame;

/**
 * Findings of two runs matched: those in both (as [a, b] pairs), only in A, only in B.
 * Each finding of B matches at most one of A.
 */
export function matchFindings(a, b) {
  const free = new Set(b.map((_, k) => k));
  const both = [], onlyA = [];
  for (const f of a) {
    const k = [...free].find((j) => sameFinding(f, b[j]));
    if (k === undefined) onlyA.push(f);
    else { free.delete(k); both.push([f, b[k]]); }
  }
  return { both, onlyA, onlyB: [...free].map((k) => b[k]) };
}

/**
 * Options that differ between two runs, flattened to dotted keys: [key, a, b] rows. Lists
 * (the checks) are compared as sets: their order does not matter. Checks named in `idle` (as
 * idleChecks gives them: asked for, but their step did nothing) are left out of the checks
 * before comparing.
 */
export function optionsDiff(a, b, idle = []) {
  const skip = new Set(idle);
  const flat = (o, prefix = "") => Object.entries(o || {}).flatMap(([k, v]) =>
    (v && typeof v === "object" && !Array.isArray(v) ? flat(v, `${prefix}${k}.`) : [[`${prefix}${k}`, k === "checks" && Array.isArray(v) ? v.filter((c) => !skip.has(c)) : v]]));
  const left = new Map(flat(a)), right = new Map(flat(b));
  const keys = [...new Set([...left.keys(), ...right.keys()])].sort();
  const show = (v) => (v === undefined ? "–" : Array.isArray(v) ? v.join(", ") : String(v));
  const same = (x, y) => (Array.isArray(x) && Array.isArray(y)
    ? new Set(x).size === new Set(y).size && x.every((v) => y.some((w) => JSON.stringify(v) === JSON.stringify(w)))
    : JSON.stringify(x) === JSON.stringify(y));
  return keys.filter((k) => !same(left.get(k), right.get(k))).map((k) => [k, show(left.get(k)), show(right.get(k))]);
}

/** The checks that make no difference between two runs' results (`steps` and `options` of
 * each): asked for by one or both, and skipped in every run that asked for it (a check the
 * take's kind cannot run, such as markers on a motion take, or a filter with none chosen). */
export function idleChecks(a, b) {
  const asked = (r, c) => ((r.options && r.options.checks) || []).includes(c);
  const skipped = (r, c) => Boolean(r.steps && r.steps[c] && r.steps[c].state === "skipped");
  const all = new Set([...((a.options && a.options.checks) || []), ...((b.options && b.options.checks) || [])]);
  return [...all].filter((c) => [a, b].every((r) => !asked(r, c) || skipped(r, c)));
}
