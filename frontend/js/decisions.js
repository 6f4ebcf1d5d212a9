// Accept / reject per correction in the findings table: the twist intervals of a motion take,
// the swaps of a marker take, and the foot locks of skate findings (lock-decisions.js). A
// decision shows at once and is saved as a row of the run's decision history (the newest per
// item counts; the other choice undoes one). Each row says what the reviewed download does with
// the item: an accepted one is corrected, a rejected one left as recorded, an undecided one
// follows the run's own choice ("run: applied"; for a foot lock the run's feet_apply, "none" by
// default: cleanup is off).
import * as api from "./api.js";
import { badge, h, toast } from "./dom.js";
import { decidableLocks, decidedLinks, downloadText, keptCount, LOCK_KIND, lockKeyTarget, lockLabel, mergedHistory, reviewedFormats, runLockText } from "./lock-decisions.js";
import { announceLockDecisions } from "./lock-events.js";

export const DECISION_KEYS = { y: "accept", x: "reject" }; // on the focused or last opened decidable row
const LABELS = { accept: "accepted", reject: "rejected" };
const BADGE = { accept: "approved", reject: "rejected" };

// Per finding kind that can be decided: the API's item, its name, the run's choice for an
// undecided one, and what the decided download is (its formats: reviewedFormats).
const DECIDED = {
  twist: {
    item: "interval", name: "twist interval",
    applied: "the run's twist_apply choice, in its corrected BVH",
    explain: "The reviewed take is the raw take with the intervals marked \u201c\u2192 corrected\u201d removed: every accepted one, and each undecided one the run applied; rejected ones are left as recorded. No motion filter. The run's own \u201ccorrected BVH\u201d (Downloads) is its choice before review.",
  },
  swap: {
    item: "swap", name: "swap",
    applied: "the run's confident rule, as in its corrected take",
    explain: "The reviewed take (C3D, or TRC for OpenSim; a TRC take's as TRC) is the raw take with the swaps marked \u201c\u2192 corrected\u201d repaired: every accepted one, and each undecided one the run repaired; rejected ones are left as recorded. Its gaps are then filled as the run fills them (the confident fills, chosen again on that take): a C3D marks each filled sample (residual 0); TRC has no residual, so the filled samples are the gap findings listed above (the run's report lists them too), and samples still missing are NaN. No filter. A C3D take's run has its own corrected C3D (Downloads): its choice before review.",
  },
  [LOCK_KIND]: {
    item: "lock", name: "foot lock", corrected: " → locked",
    ...(({ locked, notLocked, title }) => ({ appliedText: locked, notApplied: notLocked, applied: title }))(runLockText("none")),
    explain: "Foot locks are cleanup, off by default (a run's feet_apply option: none, confident, skates): the reviewed take holds the foot of each accepted skate finding, and of each undecided one the run locked, where it stands during its contact, eased in and out over 0.1 s (BVH: a two-bone leg IK, only the hips, knees and ankles turn; C3D and TRC: the foot markers are pinned), after the other corrections. Rejected ones, and undecided ones the run did not lock, are left as recorded. A C3D or TRC take's run without the markers check has locks only: its reviewed take is the raw take with those locks pinned, no swap repaired and no gap filled. Keypoint takes other than C3D and TRC marker takes have no reviewed download.",
  },
};

/** What a run's findings let a reviewer decide: `{ kind, items }` (the finding kind, "twist"
 * or "swap", and its items by id order), or null when there is nothing to decide. */
export function decidable(result) {
  const twist = result.kind === "motion" && result.series && result.series.twist;
  if (twist && twist.intervals.length) return { kind: "twist", items: twist.intervals };
  const swaps = result.kind === "keypoints" ? (result.findings || []).filter((f) => f.kind === "swap") : [];
  return swaps.length ? { kind: "swap", items: swaps } : null;
}

/** How a decided item is named, as its findings row shows it (the id is internal). */
export function itemLabel(kind, item) {
  const frames = `frames ${item.start_frame}–${item.end_frame}`;
  return kind === "swap" ? `${item.markers.join(" ↔ ")} ${frames}` : `${item.joint} ${frames}`;
}

/** The newest other finished run of `take` whose decision histories (its twist intervals or
 * swaps, and its foot locks) are not empty, with their length, or null; `getDecisions` is api.getDecisions (a parameter for tests). */
export async function decidedElsewhere(take, run, getDecisions = api.getDecisions) {
  const others = (take?.runs || []).map((r, k) => [r, k + 1]).filter(([r]) => r.id !== run.id && r.status === "done").reverse();
  for (const [other, number] of others) {
    const body = await getDecisions(other.id).catch(() => null);
    // The histories come a page at a time: their totals count every decision.
    const count = body ? (body.history_total ?? body.history.length) + (body.lock_history_total ?? (body.lock_history || []).length) : 0;
    if (count) return { run: other, number, count };
  }
  return null;
}

/** What Y / X act on: `{ id }` of the item to decide, or `{ message }` saying why there is none.
 * `focused` is the focused findings row's `{ kind, interval }` (its data attributes) or null,
 * `current` the last opened decidable item's id, `lastKind` the last opened finding's kind,
 * `kind` the decidable kind and `ids` the decidable items' ids. */
export function keyTarget(focused, current, lastKind, kind, ids) {
  const reported = (k) => ({ message: `a ${k} finding is reported, not corrected: nothing to accept or reject` });
  if (focused && !focused.interval) return reported(focused.kind);
  const id = focused ? Number(focused.interval) : current;
  if (id != null && ids.has(id)) return { id };
  return lastKind && lastKind !== kind ? reported(lastKind) : { message: `open or focus a ${kind} finding first` };
}

/** The decision history's lines, newest first as the server lists them; `label(row)` names a
 * row's item. */
function historyItems(rows, label) {
  return rows.map((r) => h("li", {}, `${new Date(r.created_at).toLocaleString()} · ${r.reviewer}: `, badge(LABELS[r.decision], BADGE[r.decision]),
    ` ${label(r)}`, r.note ? ` — ${r.note}` : ""));
}

/** Draw an item's decision cell: the run's choice, the decision, what the reviewed download
 * does with it, and the Accept / Reject buttons (`onDecide(decision)`). */
function fillCell(cell, f, decision, spec, onDecide) {
  const buttons = ["accept", "reject"].map((d) => {
    const button = h("button", { class: `small decide-${d}`, "data-decision": d, "aria-pressed": String(decision === d),
      onclick: (e) => { e.stopPropagation(); onDecide(d); } }, d === "accept" ? "Accept" : "Reject");
    // Enter or space on a button acts on the button, not on its row.
    button.addEventListener("keydown", (e) => { if (e.key === "Enter" || e.key === " ") e.stopPropagation(); });
    return button;
  });
  const corrected = decision ? decision === "accept" : Boolean(f.applied);
  // Redrawn under the keyboard's focus: the same button keeps it (screen readers and Tab
  // carry on from there instead of the page's start).
  const focused = cell.contains(document.activeElement) ? document.activeElement.dataset?.decision : null;
  // The read-out wraps on the left; the buttons keep to the cell's right, side by side.
  cell.replaceChildren(h("div", { class: "decision-cell" },
    h("span", { class: "decision-state" },
      h("span", { class: "applied muted", title: spec.applied }, f.applied ? spec.appliedText || "run: applied" : spec.notApplied || "run: not applied"), " · ",
      decision ? badge(LABELS[decision], BADGE[decision]) : h("span", { class: "muted" }, "undecided"),
      h("span", { class: "outcome muted", title: `what the reviewed download does with this ${spec.name}` }, corrected ? spec.corrected || " → corrected" : " → left as recorded")),
    h("span", { class: "decision-buttons" }, ...buttons)));
  if (focused) buttons.find((b) => b.dataset.decision === focused)?.focus();
}

/** Below the findings table: the reviewed downloads (`parts.downloads`, none for a take
 * without one), a note for the next decision, what the download is (`explains`, one paragraph
 * per decided kind), and the history. */
function decisionsFooter(explains, parts) {
  const none = "no reviewed download of this run: it is written as BVH for motion takes, and for a marker take (C3D or TRC) whose run checked its markers as C3D and TRC (a C3D take) or TRC (a TRC take); a run of a marker take without the markers check, and other keypoint takes, have none";
  return h("div", { id: "decisions" },
    parts.elsewhere,
    h("div", { class: "controls" },
      ...(parts.downloads.length ? parts.downloads.map((d) => d.link) : [h("span", { class: "muted", id: "download-decided-none" }, none)]),
      parts.note, parts.message),
    explains.map((text) => h("p", { class: "muted" }, text)),
    parts.history);
}

/** The message line, the note on another run's decisions, the note field, the download links
 * (`formats`: reviewedFormats; `download` the first) and the history list. */
function decisionParts(run, formats) {
  const downloads = decidedLinks(formats).map((d) => ({ ...d,
    link: h("a", { href: api.decidedUrl(run.id, d.format), download: "", id: d.id, class: "download" }, downloadText(0, 0, d.named)) }));
  return {
    message: h("span", { id: "decision-message", class: "muted" }),
    // Decisions belong to a run: a re-run starts undecided, and says where earlier ones are.
    elsewhere: h("p", { id: "decisions-elsewhere", class: "notice", hidden: true }),
    note: h("input", { id: "decision-note", placeholder: "note for the next decision", "aria-label": "decision note" }),
    history: h("ul", { id: "decision-history" }),
    downloads,
    download: downloads.length ? downloads[0].link : null,
  };
}

/** One decided kind of a run: its spec, items by id, newest decisions and findings-row cells;
 * `post(id, body)` saves a decision. */
function decidedGroup(kind, items, post) {
  return { kind, spec: DECIDED[kind], byId: new Map(items.map((i) => [i.id, i])), latest: new Map(), cells: new Map(), post };
}

/** The twist intervals or swaps of a run and its foot locks, as decided groups. */
function runGroups(run, result) {
  const found = decidable(result);
  const main = found ? decidedGroup(found.kind, found.items, (id, body) => api.addDecision(run.id, id, body, DECIDED[found.kind].item)) : null;
  const lockItems = decidableLocks(result);
  const locks = lockItems.length
    ? decidedGroup(LOCK_KIND, lockItems, (id, body) => api.addLockDecision(run.id, id, body))
    : null;
  if (locks) {
    const { locked, notLocked, title } = runLockText(run.options && run.options.feet_apply);
    locks.spec = { ...locks.spec, appliedText: locked, notApplied: notLocked, applied: title };
  }
  return { main, locks };
}

/** Decision cells for the findings rows of `run` and the panel parts below the table. */
export function intervalDecisions(run, result, take = null) {
  // Only a take with twist intervals, swaps or foot locks has anything to accept or reject.
  const { main, locks } = runGroups(run, result);
  const groups = [main, locks].filter(Boolean);
  const formats = reviewedFormats(result, take);
  const parts = decisionParts(run, formats);
  // Without a reviewed download a kept lock changes no file: the cell says so.
  if (locks && !formats.length) locks.spec = { ...locks.spec, corrected: " → would be locked (no reviewed download of this run)" };
  const { message, note, history } = parts;
  const opened = { main: null, lock: null, kind: null }; // the last opened item of each group, and finding kind
  const say = (text, cls) => { message.textContent = text; message.className = cls; };
  const groupOf = (kind) => groups.find((g) => g.kind === kind) || null;
  const nameOf = (g, id) => (g && g.byId.has(id) ? (g === locks ? lockLabel(g.byId.get(id)) : itemLabel(g.kind, g.byId.get(id))) : `${g ? g.spec.item : "item"} ${id}`);
  const rowLabel = (r) => (r.item === "lock" ? nameOf(locks, r.lock_id) : nameOf(main, r.interval_id));
  const showHistory = (body) => history.replaceChildren(...historyItems(mergedHistory(body.history, body.lock_history), rowLabel));
  const showDownload = () => {
    if (!locks) return;
    for (const d of parts.downloads) {
      const kept = keptCount(locks.byId, locks.latest);
      d.link.textContent = downloadText(locks.byId.size, kept, d.named);
      d.link.dataset.locks = String(kept);
    }
  };
  // The contact timeline draws the locks: it hears of every change (lock-events.js).
  const announce = (g) => { if (g && g === locks) announceLockDecisions(run.id, locks.latest); };
  const fill = (g, id) => {
    const cell = g.cells.get(id);
    const f = g.byId.get(id);
    if (cell && f) fillCell(cell, f, g.latest.get(id), g.spec, (d) => decide(g, id, d));
  };
  showDownload();

  async function decide(g, id, decision) {
    const before = g.latest.get(id);
    g.latest.set(id, decision); // shows at once; undone if the server refuses
    fill(g, id);
    announce(g);
    if (g === locks) opened.lock = id; else opened.main = id;
    try {
      // The server records the signed-in user as the reviewer.
      await g.post(id, { decision, note: note.value });
      note.value = "";
      say(`${nameOf(g, id)} ${LABELS[decision]}`, "muted");
      toast(message.textContent);
      showDownload();
      showHistory(await api.getDecisions(run.id));
    } catch (e) {
      if (before) g.latest.set(id, before); else g.latest.delete(id);
      fill(g, id);
      announce(g);
      showDownload();
      say(e.message, "error");
      toast(e.message);
    }
  }

  // The saved decisions fill the cells drawn meanwhile.
  const loaded = groups.length ? api.getDecisions(run.id).then(async (body) => {
    if (main) for (const i of main.kind === "swap" ? body.swaps : body.intervals) if (i.decision) main.latest.set(i.id, i.decision);
    if (locks) for (const l of body.locks || []) if (l.decision) locks.latest.set(l.id, l.decision);
    for (const g of groups) for (const id of g.cells.keys()) fill(g, id);
    announce(locks);
    showDownload();
    showHistory(body);
    if (!body.history.length && !(body.lock_history || []).length && take) await showElsewhere(take, run, (main || locks).spec, parts.elsewhere);
  }).catch((e) => say(e.message, "error")) : Promise.resolve();

  return decidedView({ main, locks, groups, opened, parts, loaded, decide, say, groupOf, fill });
}

/** The object the findings list and the take view use (see intervalDecisions). */
function decidedView(v) {
  const { main, locks, groups, opened, parts, loaded, decide, say, fill } = v;
  const { message } = parts;
  return {
    enabled: groups.length > 0,
    /** The finding kind whose rows are twist intervals or swaps ("twist" or "swap"), null for none. */
    kind: main ? main.kind : null,
    loaded,
    /** Whether a finding's row is a foot lock to decide. */
    isLock(f) { return Boolean(locks && f.kind === LOCK_KIND && locks.byId.has(f.id)); },
    /** The decision cell of a findings row (empty for a finding with nothing to decide). */
    cell(f) {
      const cell = h("td", { class: "decision" });
      const g = v.groupOf(f.kind);
      if (g && g.byId.has(f.id)) { g.cells.set(f.id, cell); fill(g, f.id); }
      return cell;
    },
    /** The last opened finding: Y/X act on it when it is a twist interval, a swap or a foot
     * lock, and on none after another finding (never on an item opened before it). */
    opened(f) {
      opened.main = main && f && f.kind === main.kind ? f.id : null;
      opened.lock = locks && f && f.kind === LOCK_KIND ? f.id : null;
      opened.kind = f ? f.kind : null;
    },
    /** Y / X on the focused (else the last opened) decidable row; true when the key was used. */
    onKey(e) {
      const decision = DECISION_KEYS[e.key.toLowerCase()];
      if (!decision) return false;
      if (!groups.length) { toast("this run has no twist intervals, swaps or foot locks to accept or reject"); return true; }
      const row = document.activeElement && document.activeElement.closest && document.activeElement.closest("tr.finding");
      const focused = row ? { kind: row.dataset.kind, interval: row.dataset.interval, lock: row.dataset.lock } : null;
      const lockTarget = lockKeyTarget(focused, opened.lock, opened.kind, locks ? locks.byId : new Map());
      const target = lockTarget || (main ? keyTarget(focused, opened.main, opened.kind, main.kind, main.byId) : { message: "open or focus a skate finding first" });
      if (target.message) { say(target.message, "muted"); toast(message.textContent); } else if (target.lock) decide(locks, target.lock, decision); else decide(main, target.id, decision);
      return true;
    },
    /** Below the table: the download, a note for the next decision and the history. */
    footer() { return groups.length ? decisionsFooter(groups.map((g) => g.spec.explain), parts) : null; },
  };
}

/** Say, in `elsewhere`, which other run of `take` holds decisions when this one has none. */
async function showElsewhere(take, run, spec, elsewhere) {
  const other = await decidedElsewhere(take, run);
  if (!other) return;
  elsewhere.replaceChildren(`Run ${other.number} holds ${other.count} decision${other.count === 1 ? "" : "s"} (on its ${spec.name}s or foot locks); this run has none yet (decisions belong to the run they were made on). `,
    h("a", { href: api.takeLink(take.id, other.run.id), id: "decisions-elsewhere-link" }, `open run ${other.number}`));
  elsewhere.hidden = false;
}
