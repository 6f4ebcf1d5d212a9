// Accept / reject per correction in the findings table: the twist intervals of a motion take,
// the swaps of a marker take. A decision shows at once and is saved as a row of the run's
// decision history (the newest per item counts). Each row says what the reviewed download does
// with the item: an accepted one is corrected, a rejected one left as recorded, an undecided one
// follows the run's own choice ("run: applied").
import * as api from "./api.js";
import { badge, h, toast } from "./dom.js";

export const DECISION_KEYS = { y: "accept", x: "reject" }; // on the focused or last opened decidable row
const LABELS = { accept: "accepted", reject: "rejected" };
const BADGE = { accept: "approved", reject: "rejected" };

// Per finding kind that can be decided: the API's item, its name, the run's choice for an
// undecided one, the decided download's format, and what that download is.
const DECIDED = {
  twist: {
    item: "interval", name: "twist interval", format: "bvh",
    applied: "the run's twist_apply choice, in its corrected BVH",
    explain: "The reviewed take is the raw take with the intervals marked \u201c\u2192 corrected\u201d removed: every accepted one, and each undecided one the run applied; rejected ones are left as recorded. No motion filter. The run's own \u201ccorrected BVH\u201d (Downloads) is its choice before review.",
  },
  swap: {
    item: "swap", name: "swap", format: "c3d",
    applied: "the run's confident rule, in its corrected C3D",
    explain: "The reviewed take (C3D) is the raw take with the swaps marked \u201c\u2192 corrected\u201d repaired: every accepted one, and each undecided one the run repaired; rejected ones are left as recorded. Its gaps are then filled as the run fills them (the confident fills, chosen again on that take), filled samples marked (residual 0). No filter. The run's own corrected C3D (Downloads) is its choice before review.",
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

/** The newest other finished run of `take` whose decision history is not empty, with that
 * history's length, or null; `getDecisions` is api.getDecisions (a parameter for tests). */
export async function decidedElsewhere(take, run, getDecisions = api.getDecisions) {
  const others = (take?.runs || []).map((r, k) => [r, k + 1]).filter(([r]) => r.id !== run.id && r.status === "done").reverse();
  for (const [other, number] of others) {
    const body = await getDecisions(other.id).catch(() => null);
    if (body && body.history.length) return { run: other, number, count: body.history.length };
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

/** The decision history's lines, newest last as the server lists them; `label(id)` names an item. */
function historyItems(rows, label) {
  return rows.map((r) => h("li", {}, `${new Date(r.created_at).toLocaleString()} · ${r.reviewer}: `, badge(LABELS[r.decision], BADGE[r.decision]),
    ` ${label(r.interval_id)}`, r.note ? ` — ${r.note}` : ""));
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
  const corrected = decision ? decision === "accept" : f.applied;
  // Redrawn under the keyboard's focus: the same button keeps it (screen readers and Tab
  // carry on from there instead of the page's start).
  const focused = cell.contains(document.activeElement) ? document.activeElement.dataset?.decision : null;
  // The read-out wraps on the left; the buttons keep to the cell's right, side by side.
  cell.replaceChildren(h("div", { class: "decision-cell" },
    h("span", { class: "decision-state" },
      h("span", { class: "applied muted", title: spec.applied }, f.applied ? "run: applied" : "run: not applied"), " · ",
      decision ? badge(LABELS[decision], BADGE[decision]) : h("span", { class: "muted" }, "undecided"),
      h("span", { class: "outcome muted", title: `what the reviewed download does with this ${spec.name}` }, corrected ? " → corrected" : " → left as recorded")),
    h("span", { class: "decision-buttons" }, ...buttons)));
  if (focused) buttons.find((b) => b.dataset.decision === focused)?.focus();
}

/** Below the findings table: the reviewed download, a note for the next decision, what the
 * download is, and the history. */
function decisionsFooter(run, result, spec, parts) {
  // A marker take's reviewed download is C3D, for a take the run wrote a corrected C3D of.
  const downloadable = spec.format !== "c3d" || (result.downloads || []).includes("c3d");
  return h("div", { id: "decisions" },
    parts.elsewhere,
    h("div", { class: "controls" },
      downloadable
        ? h("a", { href: api.decidedUrl(run.id, spec.format), download: "", id: "download-decided", class: "download" }, "Download reviewed take")
        : h("span", { class: "muted", id: "download-decided-none" }, "no reviewed download: it is written as C3D, for C3D takes"),
      parts.note, parts.message),
    h("p", { class: "muted" }, spec.explain),
    parts.history);
}

/** The message line, the note on another run's decisions, the note field and the history list. */
function decisionParts() {
  return {
    message: h("span", { id: "decision-message", class: "muted" }),
    // Decisions belong to a run: a re-run starts undecided, and says where earlier ones are.
    elsewhere: h("p", { id: "decisions-elsewhere", class: "notice", hidden: true }),
    note: h("input", { id: "decision-note", placeholder: "note for the next decision", "aria-label": "decision note" }),
    history: h("ul", { id: "decision-history" }),
  };
}

/** Decision cells for the findings rows of `run` and the panel parts below the table. */
export function intervalDecisions(run, result, take = null) {
  // Only a take with twist intervals or swaps has anything to accept or reject.
  const found = decidable(result);
  const kind = found ? found.kind : null;
  const spec = kind ? DECIDED[kind] : null;
  const latest = new Map(); // item id -> "accept" | "reject"
  const cells = new Map(); // item id -> the row's decision cell
  let current = null; // the last opened decidable item
  let lastKind = null; // the kind of the last opened finding
  const parts = decisionParts();
  const { message, note, history } = parts;
  const byId = new Map((found ? found.items : []).map((i) => [i.id, i]));
  const say = (text, cls) => { message.textContent = text; message.className = cls; };

  const label = (id) => (byId.has(id) ? itemLabel(kind, byId.get(id)) : `${spec ? spec.item : "item"} ${id}`);
  const showHistory = (rows) => history.replaceChildren(...historyItems(rows, label));
  const fill = (id) => {
    const cell = cells.get(id);
    const f = byId.get(id);
    if (cell && f) fillCell(cell, f, latest.get(id), spec, (d) => decide(id, d));
  };

  async function decide(id, decision) {
    const before = latest.get(id);
    latest.set(id, decision); // shows at once; undone if the server refuses
    fill(id);
    current = id;
    try {
      // The server records the signed-in user as the reviewer.
      await api.addDecision(run.id, id, { decision, note: note.value }, spec.item);
      note.value = "";
      say(`${label(id)} ${LABELS[decision]}`, "muted");
      toast(message.textContent);
      showHistory((await api.getDecisions(run.id)).history);
    } catch (e) {
      if (before) latest.set(id, before); else latest.delete(id);
      fill(id);
      say(e.message, "error");
      toast(e.message);
    }
  }

  // The saved decisions fill the cells drawn meanwhile.
  const loaded = found ? api.getDecisions(run.id).then(async (body) => {
    for (const i of kind === "swap" ? body.swaps : body.intervals) if (i.decision) latest.set(i.id, i.decision);
    for (const id of cells.keys()) fill(id);
    showHistory(body.history);
    if (!body.history.length && take) await showElsewhere(take, run, spec, parts.elsewhere);
  }).catch((e) => say(e.message, "error")) : Promise.resolve();

  return {
    enabled: Boolean(found),
    /** The finding kind whose rows are decided ("twist" or "swap"), null for none. */
    kind,
    loaded,
    /** The decision cell of a findings row (empty for a limits finding). */
    cell(f) {
      const cell = h("td", { class: "decision" });
      if (found && f.kind === kind && byId.has(f.id)) { cells.set(f.id, cell); fill(f.id); }
      return cell;
    },
    /** The last opened finding: Y/X act on it when it is a twist interval (a swap), and on
     * none after another finding (never on an item opened before it). */
    opened(f) { current = f && f.kind === kind ? f.id : null; lastKind = f ? f.kind : null; },
    /** Y / X on the focused (else the last opened) decidable row; true when the key was used. */
    onKey(e) {
      const decision = DECISION_KEYS[e.key.toLowerCase()];
      if (!decision) return false;
      if (!found) { toast("this run has no twist intervals or swaps to accept or reject"); return true; }
      const row = document.activeElement && document.activeElement.closest && document.activeElement.closest("tr.finding");
      const target = keyTarget(row ? { kind: row.dataset.kind, interval: row.dataset.interval } : null, current, lastKind, kind, byId);
      if (target.message) { say(target.message, "muted"); toast(message.textContent); } else decide(target.id, decision);
      return true;
    },
    /** Below the table: the download, a note for the next decision and the history. */
    footer() { return found ? decisionsFooter(run, result, spec, parts) : null; },
  };
}

/** Say, in `elsewhere`, which other run of `take` holds decisions when this one has none. */
async function showElsewhere(take, run, spec, elsewhere) {
  const other = await decidedElsewhere(take, run);
  if (!other) return;
  elsewhere.replaceChildren(`Run ${other.number} holds ${other.count} decision${other.count === 1 ? "" : "s"} on its ${spec.name}s; this run has none yet (decisions belong to the run they were made on). `,
    h("a", { href: api.takeLink(take.id, other.run.id), id: "decisions-elsewhere-link" }, `open run ${other.number}`));
  elsewhere.hidden = false;
}
