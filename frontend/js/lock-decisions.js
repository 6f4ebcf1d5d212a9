// Foot locks in the findings table: each skate finding of the feet step has a lock (the foot
// held where it stands during the contact) a reviewer accepts or rejects like a twist interval.
// The reviewed download locks the accepted ones, and the undecided ones the run locked (its
// feet_apply choice, the finding's `applied`; cleanup is off by default, so a default run locks
// none). Pure helpers of decisions.js (unit-tested).

/** The finding kind whose rows carry a foot lock. */
export const LOCK_KIND = "skate";

/** The run's foot locks: its skate findings that have an id (`skate-left-120`), in findings order. */
export function decidableLocks(result) {
  return (result.findings || []).filter((f) => f.kind === LOCK_KIND && typeof f.id === "string" && f.id);
}

/** How a lock is named in the history and the messages. */
export function lockLabel(lock) {
  return `${lock.foot} foot lock frames ${lock.start_frame}–${lock.end_frame}`;
}

/** The formats of the run's reviewed download, the take's own first: ["bvh"] for a motion
 * take; for a marker take whose markers check ran, or whose feet check found foot locks (the
 * raw take with the accepted locks pinned), ["c3d", "trc"] for a C3D take (TRC for OpenSim)
 * and ["trc"] for a TRC take (`take.format`); none for other keypoint takes. */
export function reviewedFormats(result, take = null) {
  if (result.kind === "motion") return ["bvh"];
  if ((result.downloads || []).includes("c3d")) return ["c3d", "trc"];
  const done = (step) => Boolean(result.steps && result.steps[step] && result.steps[step].state === "done");
  const decided = done("markers") || (done("feet") && decidableLocks(result).length > 0);
  if (!decided || !take) return [];
  if (take.format === "c3d") return ["c3d", "trc"];
  return take.format === "trc" ? ["trc"] : [];
}

/** The format of the run's first reviewed download (reviewedFormats), or null when it has none. */
export function reviewedFormat(result, take = null) {
  return reviewedFormats(result, take)[0] || null;
}

/** The reviewed download links of `formats` (reviewedFormats), the first one's id
 * `download-decided`, the others' `download-decided-<format>`; `named` is the format a link
 * names (a marker take's: "c3d" or "trc"), null for BVH. */
export function decidedLinks(formats) {
  return formats.map((format, k) => ({ format, id: k ? `download-decided-${format}` : "download-decided", named: format === "bvh" ? null : format }));
}

/** Whether the reviewed download locks `lock` (a skate finding, `applied` when the run locked
 * it) under its newest `decision` ("accept" | "reject" | undefined): accepted, or undecided and
 * locked by the run. */
export function lockKept(lock, decision) {
  return decision ? decision === "accept" : Boolean(lock.applied);
}

/** How many of `locks` (a Map of id -> skate finding) the reviewed download locks under the
 * newest decisions `latest` (id -> "accept" | "reject"). */
export function keptCount(locks, latest) {
  let n = 0;
  for (const [id, lock] of locks) if (lockKept(lock, latest.get(id))) n += 1;
  return n;
}

/** What a foot lock's decision cell says of the run's own choice, by the run's `feet_apply`
 * ("none" by default; "confident", "skates" or skate ids): `locked` / `notLocked` the cell's
 * text for a lock the run locked or did not, `title` its explanation. */
export function runLockText(feetApply) {
  const choice = feetApply || "none";
  if (choice === "none") {
    return { locked: "run: locked", notLocked: "run: cleanup off",
      title: "foot cleanup is off by default: the run locks no foot, the reviewed take locks the accepted ones" };
  }
  return { locked: "run: locked", notLocked: "run: not locked",
    title: `the run's feet_apply choice (${choice}), in its corrected take; the reviewed take locks the accepted ones and the undecided ones the run locked` };
}

/** The reviewed download link's text: its format when a marker take has it named (`format`,
 * "c3d" or "trc"; null for BVH), and how many of the run's `nLocks` foot locks it applies
 * (`kept`: keptCount), when the run has any: "Download reviewed take (0 of 5 foot locks
 * applied)". */
export function downloadText(nLocks, kept, format = null) {
  const base = format ? `Download reviewed take as ${format.toUpperCase()}` : "Download reviewed take";
  if (!nLocks) return base;
  return `${base} (${kept} of ${nLocks} foot lock${nLocks === 1 ? "" : "s"} applied)`;
}

/** Both decision histories (twist intervals or swaps, and foot locks) as one list, newest first
 * (ids grow with time: they are rows of one table). */
export function mergedHistory(history, lockHistory) {
  return [...history, ...(lockHistory || [])].sort((a, b) => b.id - a.id);
}

/** What Y / X act on when it is a foot lock: `{ lock }` (its id), `{ message }` when a skate
 * row has no lock to decide, or null when the key is not about a foot lock (the focused row, or
 * without one the last opened finding, is of another kind). `focused` is the focused findings
 * row's `{ kind, lock }` (its data attributes) or null, `current` the last opened lock's id. */
export function lockKeyTarget(focused, current, lastKind, ids) {
  const kind = focused ? focused.kind : lastKind;
  if (kind !== LOCK_KIND) return null;
  const id = focused ? focused.lock : current;
  if (id && ids.has(id)) return { lock: id };
  return { message: "this skate finding has no foot lock to accept or reject" };
}
