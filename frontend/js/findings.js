// Pure functions of the findings list: filters, groups by joint, the finding at a frame and the
// range that loops a finding (no DOM).
import { sortFindings } from "./format.js";

/** Magnitude of a finding's value (offset or distance outside the limits), or null. */
export const magnitude = (f) => (f.value == null ? null : Math.abs(f.value));

/**
 * The findings a filter keeps.
 *
 * @param findings  the run's findings
 * @param filter    {kinds?: Set of kinds kept (all when empty or absent), joint?: one joint name
 *                  ("" or absent: all), minValue?: smallest |value| kept (a finding without a
 *                  value is kept only when there is no minimum), text?: words that must all be
 *                  found, case-blind, in the kind, the joint, the frames or the read-out}
 */
export function filterFindings(findings, filter = {}) {
  const kinds = filter.kinds && filter.kinds.size ? filter.kinds : null;
  const words = String(filter.text || "").toLowerCase().split(/\s+/).filter(Boolean);
  const least = filter.minValue == null || filter.minValue === "" || Number.isNaN(Number(filter.minValue)) ? null : Number(filter.minValue);
  return findings.filter((f) => {
    if (kinds && !kinds.has(f.kind)) return false;
    if (filter.joint && f.joint !== filter.joint) return false;
    if (least != null && !(magnitude(f) >= least)) return false;
    if (!words.length) return true;
    const haystack = `${f.kind} ${f.joint} ${f.start_frame}–${f.end_frame} ${f.readout || ""}`.toLowerCase();
    // A typed hyphen also matches the en dash of the frame ranges ("161-161" finds "161–161").
    return words.every((w) => haystack.includes(w) || haystack.includes(w.replace(/-/g, "–")));
  });
}

/**
 * Findings grouped by joint: [{joint, rows, count, worst, kinds}], rows sorted by `key` and
 * `dir` (as sortFindings), groups ordered by their first row under the same order (so sorting by
 * magnitude puts the joint with the worst finding first). `worst` is the largest |value|.
 */
export function groupByJoint(findings, key = "start_frame", dir = 1) {
  const sorted = sortFindings(findings, key, dir);
  const groups = new Map();
  for (const f of sorted) {
    if (!groups.has(f.joint)) groups.set(f.joint, { joint: f.joint, rows: [], count: 0, worst: null, kinds: new Set() });
    const g = groups.get(f.joint);
    g.rows.push(f);
    g.count += 1;
    g.kinds.add(f.kind);
    const m = magnitude(f);
    if (m != null && (g.worst == null || m > g.worst)) g.worst = m;
  }
  return [...groups.values()];
}

/** The rows in the order the list shows them (groups one after another). */
export const listOrder = (groups) => groups.flatMap((g) => g.rows);

/** The finding whose frames hold `frame` (the first in `findings` order), else null. */
export const findingAt = (findings, frame) => findings.find((f) => f.start_frame <= frame && frame <= f.end_frame) || null;

/** Joints inside a finding at frame `f`, as joint index → colour (`colorOf(finding)`); a later
 * finding on the same joint wins. Findings on joints not in `jointIndex` (name → index) are
 * left out. */
export function flaggedAt(findings, jointIndex, f, colorOf) {
  const flagged = new Map();
  for (const x of findings) if (jointIndex.has(x.joint) && f >= x.start_frame && f <= x.end_frame) flagged.set(jointIndex.get(x.joint), colorOf(x));
  return flagged;
}

/** Frames that loop a finding: its frames with `margin` frames either side, inside the take. */
export function loopOfFinding(f, margin, nFrames) {
  return [Math.max(0, f.start_frame - margin), Math.min(nFrames - 1, f.end_frame + margin)];
}

/** The kinds of the findings, in order of first appearance. */
export const kindsOf = (findings) => [...new Set(findings.map((f) => f.kind))];

/** Joint names with findings, sorted by name. */
export const jointsOf = (findings) => [...new Set(findings.map((f) => f.joint))].sort();

/**
 * A filter as link parameters, only those that narrow the list: `kinds` (comma-separated, when
 * not every kind of `allKinds` is kept), `only` (one joint), `atleast` (smallest |value|), `q`
 * (words).
 */
export function filterParams(filter, allKinds) {
  const out = {};
  if (filter.kinds && filter.kinds.size && !allKinds.every((k) => filter.kinds.has(k))) out.kinds = [...filter.kinds].join(",");
  if (filter.joint) out.only = filter.joint;
  if (filter.minValue != null && Number.isFinite(Number(filter.minValue))) out.atleast = String(filter.minValue);
  if (filter.text) out.q = filter.text;
  return out;
}

/**
 * The filter a link's parameters (URLSearchParams) describe (filterParams' inverse): unknown
 * kinds and joints and a minimum that is not a number are left out.
 */
export function filterFromParams(params, allKinds, allJoints) {
  const kinds = (params.get("kinds") || "").split(",").filter((k) => allKinds.includes(k) || k === "none");
  const joint = params.get("only") || "";
  const least = params.get("atleast");
  return {
    kinds: new Set(kinds),
    joint: allJoints.includes(joint) ? joint : "",
    minValue: least != null && least !== "" && Number.isFinite(Number(least)) ? Number(least) : null,
    text: params.get("q") || "",
  };
}
