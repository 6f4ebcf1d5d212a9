// Pure functions of the findings list: filters, groups by joint, the finding at a frame, the
// range that loops a finding, units and the probability a twist decision used (no DOM).
import { FINDING_KEYS, fmt, sortFindings } from "./format.js";

/** Magnitude of a finding's value (offset or distance outside the limits), or null. */
export const magnitude = (f) => (f.value == null ? null : Math.abs(f.value));

const UNIT_LABELS = { deg: "°" };
/** A unit as the list shows it ("deg" → "°", "% height" as is; "" for none). */
export const unitLabel = (unit) => UNIT_LABELS[unit] ?? unit ?? "";
/** The unit of a finding's value as its JSON names it ("deg", "% height", "cm"…; "" for none). */
export const unitOf = (f) => f.unit ?? "";
/** The units of the findings that have a value, in order of first appearance. */
export const unitsOf = (findings) => [...new Set(findings.filter((f) => f.value != null).map(unitOf))];

/** A sort order of findings: `key` one of FINDING_KEYS, `dir` 1 ascending or −1. */
export const DEFAULT_SORT = { key: "start_frame", dir: 1 };

/**
 * The findings a filter keeps.
 *
 * @param findings  the run's findings
 * @param filter    {kinds?: Set of kinds kept (all when empty or absent), joint?: one joint name
 *                  ("" or absent: all), minValue?: smallest |value| kept (a finding without a
 *                  value is kept only when there is no minimum), unit?: the unit minValue is in
 *                  ("deg", "% height"…): with a minimum, only findings in that unit are kept
 *                  ("" or absent: the minimum applies to every unit), text?: words that must
 *                  all be found, case-blind, in the kind, the joint, the frames or the read-out}
 */
export function filterFindings(findings, filter = {}) {
  const kinds = filter.kinds && filter.kinds.size ? filter.kinds : null;
  const words = String(filter.text || "").toLowerCase().split(/\s+/).filter(Boolean);
  const least = filter.minValue == null || filter.minValue === "" || Number.isNaN(Number(filter.minValue)) ? null : Number(filter.minValue);
  return findings.filter((f) => {
    if (kinds && !kinds.has(f.kind)) return false;
    if (filter.joint && f.joint !== filter.joint) return false;
    if (least != null && filter.unit && unitOf(f) !== filter.unit) return false;
    if (least != null && !(magnitude(f) >= least)) return false;
    if (!words.length) return true;
    const haystack = `${f.kind} ${f.joint} ${f.start_frame}–${f.end_frame} ${f.readout || ""}`.toLowerCase();
    // A typed hyphen also matches the en dash of the frame ranges ("161-161" finds "161–161").
    return words.every((w) => haystack.includes(w) || haystack.includes(w.replace(/-/g, "–")));
  });
}

/**
 * Findings grouped by joint: [{joint, rows, count, worst, worstByUnit, kinds}], rows sorted by
 * `key` and `dir` (as sortFindings, `keys` its sort keys), groups ordered by their first row
 * under the same order (so sorting by magnitude puts the joint with the worst finding first).
 * `worst` is the largest |value| whatever its unit; `worstByUnit` the largest |value| of each
 * unit, as [unit, value] pairs, largest first (a joint's findings may be in degrees and in
 * % height: each worst keeps its own unit).
 */
export function groupByJoint(findings, key = "start_frame", dir = 1, keys = FINDING_KEYS) {
  const sorted = sortFindings(findings, key, dir, keys);
  const groups = new Map();
  const worsts = new Map(); // joint -> unit -> largest |value|
  for (const f of sorted) {
    if (!groups.has(f.joint)) { groups.set(f.joint, { joint: f.joint, rows: [], count: 0, worst: null, worstByUnit: [], kinds: new Set() }); worsts.set(f.joint, new Map()); }
    const g = groups.get(f.joint);
    g.rows.push(f);
    g.count += 1;
    g.kinds.add(f.kind);
    const m = magnitude(f);
    if (m == null) continue;
    if (g.worst == null || m > g.worst) g.worst = m;
    const byUnit = worsts.get(f.joint);
    if (!byUnit.has(unitOf(f)) || m > byUnit.get(unitOf(f))) byUnit.set(unitOf(f), m);
  }
  for (const g of groups.values()) g.worstByUnit = [...worsts.get(g.joint)].sort((x, y) => y[1] - x[1]);
  return [...groups.values()];
}

/** A group's worst values, each with its unit, largest first: "135.3 °, 4.6 % height" ("" for
 * a group without values). */
export const worstText = (g) => g.worstByUnit.map(([unit, value]) => `${fmt(value, 1)} ${unitLabel(unit)}`.trim()).join(", ");

/**
 * The probability a twist interval's decision used: its calibrated probability moved by a
 * shoot's reviewer prior (`reviewer_probability` of the interval's `evidence`, in the run's
 * `series.twist.intervals`, or of the finding itself), else null (no prior moved it).
 *
 * @param f         a finding
 * @param intervals twist intervals by id (Map), or null
 */
export function usedProbability(f, intervals = null) {
  if (f.kind !== "twist") return null;
  const interval = intervals && intervals.get(f.id);
  const moved = interval && interval.evidence ? interval.evidence.reviewer_probability : f.reviewer_probability;
  return moved == null || !Number.isFinite(Number(moved)) ? null : Number(moved);
}

/** The confidence cell's text: a twist interval's probability in %, "11 % → 62 %" when a
 * reviewer prior moved it (`used`: usedProbability); another finding's confidence as is. */
export function confidenceText(f, used = null) {
  if (f.kind !== "twist") return fmt(f.confidence, 2);
  const calibrated = `${fmt(100 * f.confidence, 0)} %`;
  return used == null ? calibrated : `${calibrated} → ${fmt(100 * used, 0)} %`;
}

/** The sort keys of the findings list: FINDING_KEYS, the confidence of a twist interval being
 * the probability its decision used (usedProbability). */
export const listSortKeys = (intervals = null) => ({ ...FINDING_KEYS, confidence: (f) => usedProbability(f, intervals) ?? f.confidence });

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
 * A filter and the list's order as link parameters, only those that differ from the defaults:
 * `kinds` (comma-separated, when not every kind of `allKinds` is kept), `only` (one joint),
 * `atleast` (smallest |value|) and `unit` (its unit), `q` (words), `sort` (a FINDING_KEYS key
 * other than the start frame's) and `order` ("desc" for a descending order).
 */
export function filterParams(filter, allKinds) {
  const out = {};
  if (filter.kinds && filter.kinds.size && !allKinds.every((k) => filter.kinds.has(k))) out.kinds = [...filter.kinds].join(",");
  if (filter.joint) out.only = filter.joint;
  if (filter.minValue != null && Number.isFinite(Number(filter.minValue))) {
    out.atleast = String(filter.minValue);
    if (filter.unit) out.unit = filter.unit;
  }
  if (filter.text) out.q = filter.text;
  if (filter.sortKey && filter.sortKey !== DEFAULT_SORT.key) out.sort = filter.sortKey;
  if (filter.sortDir === -1) out.order = "desc";
  return out;
}

/**
 * The filter and order a link's parameters (URLSearchParams) describe (filterParams' inverse):
 * unknown kinds, joints and sort keys and a minimum that is not a number are left out.
 */
export function filterFromParams(params, allKinds, allJoints) {
  const kinds = (params.get("kinds") || "").split(",").filter((k) => allKinds.includes(k) || k === "none");
  const joint = params.get("only") || "";
  const least = params.get("atleast");
  const sortKey = params.get("sort");
  return {
    kinds: new Set(kinds),
    joint: allJoints.includes(joint) ? joint : "",
    minValue: least != null && least !== "" && Number.isFinite(Number(least)) ? Number(least) : null,
    unit: params.get("unit") || "",
    text: params.get("q") || "",
    sortKey: sortKey && Object.hasOwn(FINDING_KEYS, sortKey) ? sortKey : DEFAULT_SORT.key,
    sortDir: params.get("order") === "desc" ? -1 : DEFAULT_SORT.dir,
  };
}
