// Shoots: the list (#/shoots), one shoot's take table with import, live progress, export and
// the violations heat map (#/shoot/ID), and its review queue (#/shoot/ID/review).
// The table is sorted, filtered and paged on the server; its state lives in the URL.
import * as api from "./api.js";
import { me } from "./account-api.js";
import { activatable, h, REVIEW } from "./dom.js";
import { fmt } from "./format.js";
import { limitsModelPanel } from "./shoot-limits.js";
import {
  decisionForKey, deleteConfirmed, exportQuery, formatCell, heatmapChanged, importLines, isFiltered, progressSummary, scoreColor,
  shootControls, TAKE_COLUMNS, tableState, viewQuery,
} from "./shoot-format.js";
import { createHeatmap } from "./shoot-heatmap.js";
import { allColumnsToggle, createTakeTable, filterBar } from "./shoot-table.js";

const POLL_MS = 1000;

export async function shootsView(main) {
  const shoots = await api.listShoots();
  const name = h("input", { id: "shoot-name", placeholder: "new shoot name", "aria-label": "new shoot name", required: true });
  const message = h("span", { id: "shoot-message", class: "error" });
  const form = h("form", { class: "controls", id: "shoot-create" }, name, h("button", { class: "primary", type: "submit" }, "create shoot"), message);
  form.addEventListener("submit", async (e) => {
    e.preventDefault();
    try {
      const shoot = await api.createShoot(name.value.trim());
      location.hash = api.shootLink(shoot.id);
    } catch (error) { message.textContent = error.message; }
  });
  const counts = (c) => ["queued", "running", "done", "failed"].map((s) => h("td", {}, c[s] || 0));
  const rows = shoots.map((s) => activatable(h("tr", { class: "clickable", "data-shoot": s.id, "aria-label": `open ${s.name}` },
    h("td", { class: "name" }, s.name), h("td", {}, s.n_takes), h("td", { class: "narrow-hide" }, s.n_frames), counts(s.status_counts),
    h("td", { class: "narrow-hide" }, s.review_counts.unreviewed || 0)), () => { location.hash = api.shootLink(s.id); }));
  main.replaceChildren(h("h1", {}, `Shoots (${shoots.length})`), form,
    h("table", { id: "shoot-list" }, h("thead", {}, h("tr", {}, ["name", "takes", "frames", "queued", "running", "done", "failed", "unreviewed"].map((c, k) =>
      h("th", { class: k === 2 || k === 7 ? "narrow-hide" : null }, c)))), h("tbody", {}, rows)),
    ...(shoots.length ? [] : [h("p", { class: "muted" }, "No shoot yet: create one, then import its takes.")]));
  main.dataset.ready = "1";
}

/** Every file of a drop, folders walked recursively (DataTransfer items → file system entries). */
async function droppedFiles(dataTransfer) {
  const entries = [...dataTransfer.items].map((item) => item.webkitGetAsEntry && item.webkitGetAsEntry()).filter(Boolean);
  if (!entries.length) return [...dataTransfer.files];
  const files = [];
  const walk = async (entry) => {
    if (entry.isFile) files.push(await new Promise((resolve, reject) => entry.file(resolve, reject)));
    else if (entry.isDirectory) {
      const reader = entry.createReader();
      for (;;) {
        const batch = await new Promise((resolve, reject) => reader.readEntries(resolve, reject));
        if (!batch.length) break;
        for (const child of batch) await walk(child);
      }
    }
  };
  for (const entry of entries) await walk(entry);
  return files;
}

function importPanel(shootId, onImported) {
  const result = h("div", { id: "import-result" });
  const filesInput = h("input", { type: "file", id: "import-files", multiple: true, hidden: true });
  const folderInput = h("input", { type: "file", id: "import-folder", webkitdirectory: true, multiple: true, hidden: true });
  const send = async (files) => {
    if (!files.length) return;
    const bar = h("progress", { id: "import-progress", max: 1, value: 0 });
    const text = h("span", {}, `sending ${files.length} file(s)…`);
    result.replaceChildren(h("p", { class: "muted", id: "import-busy" }, bar, " ", text));
    const sent = (loaded, total) => {
      bar.value = loaded / total;
      text.textContent = loaded < total ? `sending ${files.length} file(s): ${fmt(loaded / 1e6, 1)} of ${fmt(total / 1e6, 1)} MB`
        : `${files.length} file(s) sent; the server is unpacking and registering them…`;
    };
    try {
      const lines = importLines(await api.importIntoShoot(shootId, files, sent));
      const list = (id, title, items, cls) => h("div", { id, class: cls }, h("strong", {}, `${title} (${items.length})`),
        items.length ? h("ul", {}, items.map((t) => h("li", {}, t))) : null);
      result.replaceChildren(list("import-kept", "kept", lines.kept, ""), list("import-skipped", "skipped", lines.skipped, "muted"),
        list("import-failed", "failed", lines.failed, lines.failed.length ? "error" : "muted"));
    } catch (e) {
      result.replaceChildren(h("p", { class: "error", id: "import-error" }, `Import refused: ${e.message}`));
    }
    onImported();
  };
  filesInput.addEventListener("change", () => send([...filesInput.files]));
  folderInput.addEventListener("change", () => send([...folderInput.files]));
  const zone = h("div", { class: "dropzone", id: "import-zone" },
    h("p", {}, "Drop takes, folders or .zip / .tar.gz archives here, or ",
      h("button", { type: "button", onclick: () => filesInput.click() }, "choose files"), " ",
      h("button", { type: "button", onclick: () => folderInput.click() }, "choose a folder")),
    filesInput, folderInput);
  zone.addEventListener("dragover", (e) => { e.preventDefault(); zone.classList.add("over"); });
  zone.addEventListener("dragleave", () => zone.classList.remove("over"));
  zone.addEventListener("drop", (e) => {
    e.preventDefault(); zone.classList.remove("over");
    droppedFiles(e.dataTransfer).then(send);
  });
  return h("div", {}, zone, result);
}

/** A modal dialog (native <dialog>: focus moves into it, Escape closes it and the focus goes
 * back to the button that opened it) holding a form; `submit` gets the form's message line. */
function formDialog(id, title, fields, submitLabel, submit) {
  const message = h("p", { class: "error", id: `${id}-message`, role: "alert" });
  const save = h("button", { type: "submit", class: "primary", id: `${id}-submit` }, submitLabel);
  const dialog = h("dialog", { id, "aria-labelledby": `${id}-title` });
  const form = h("form", { class: "dialog-form" }, h("h2", { id: `${id}-title` }, title), ...fields, message,
    h("div", { class: "controls" }, save, h("button", { type: "button", id: `${id}-cancel`, onclick: () => dialog.close() }, "cancel")));
  form.addEventListener("submit", async (e) => {
    e.preventDefault();
    save.disabled = true;
    try { await submit(); } catch (error) { message.textContent = error.message; } finally { save.disabled = false; }
  });
  dialog.append(form);
  dialog.addEventListener("close", () => { message.textContent = ""; });
  return { dialog, save, message };
}

/** Rename and delete controls of a shoot, for the roles that may use them (shootControls). */
function manageControls(shoot, who, onRenamed) {
  const allowed = shootControls(who, shoot);
  const out = [];
  if (allowed.rename) {
    const name = h("input", { id: "rename-name", "aria-label": "new name", required: true, autocomplete: "off" });
    const { dialog } = formDialog("rename-dialog", "Rename the shoot", [h("label", {}, "name ", name)], "rename", async () => {
      const renamed = await api.renameShoot(shoot.id, name.value.trim());
      shoot.name = renamed.name;
      dialog.close();
      onRenamed(renamed);
    });
    const open = h("button", { type: "button", id: "shoot-rename-open", onclick: () => { name.value = shoot.name; dialog.showModal(); name.select(); } }, "rename…");
    out.push(open, dialog);
  }
  if (allowed.delete) {
    const typed = h("input", { id: "delete-confirm", "aria-label": "shoot name, to confirm", autocomplete: "off", spellcheck: "false" });
    const what = h("p", { id: "delete-what" });
    const { dialog, save } = formDialog("delete-dialog", "Delete the shoot", [what, h("label", {}, "shoot name ", typed)], "delete shoot and takes", async () => {
      if (!deleteConfirmed(typed.value, shoot.name)) return;
      await api.deleteShoot(shoot.id, typed.value);
      dialog.close();
      location.hash = "#/shoots";
    });
    save.classList.add("danger");
    const check = () => { save.disabled = !deleteConfirmed(typed.value, shoot.name); };
    typed.addEventListener("input", check);
    const describe = (n) => what.replaceChildren("This deletes ", h("strong", {}, shoot.name), ` and its ${n} take(s), with their runs, reviews and files. `,
      "It cannot be undone. Type the shoot's name to confirm.");
    const open = h("button", { type: "button", id: "shoot-delete-open", class: "danger", onclick: () => {
      describe(shoot.n_takes);
      typed.value = ""; check(); dialog.showModal(); typed.focus();
      api.getShoot(shoot.id).then((now) => { shoot.n_takes = now.n_takes; describe(now.n_takes); }).catch(() => {}); // imports since
    } }, "delete…");
    out.push(open, dialog);
  }
  return out;
}

export async function shootView(main, shootId, params, onTeardown) {
  let state = tableState(params);
  const [shoot, who] = await Promise.all([api.getShoot(shootId), me().catch(() => null)]);
  // Runs queued from the model panel show their progress and redraw the table as they finish.
  const modelPanel = await limitsModelPanel(shoot, who, () => progress.restart());
  const title = h("span", { id: "shoot-title" }, shoot.name);
  const tableBox = h("div", { id: "take-table-box" });
  const tableArea = h("div", { id: "shoot-table-area" });
  const life = { alive: true, timer: null };
  onTeardown(() => { life.alive = false; clearTimeout(life.timer); });
  const isAlive = () => life.alive;
  const table = createTakeTable(shootId, tableArea, tableBox, () => state, apply, isAlive);
  const heatmap = createHeatmap(shootId, () => state, isAlive);
  const showError = (e) => tableArea.prepend(h("p", { class: "error" }, e.message));
  const exports = exportLinks(shootId);
  exports.label(state);
  function apply(change) {
    const patch = typeof change === "function" ? change(state) : change;
    const resetsPage = !("offset" in patch);
    const before = state;
    state = { ...state, ...patch, ...(resetsPage ? { offset: 0 } : {}) };
    history.replaceState(null, "", api.shootLink(shootId, viewQuery(state)));
    exports.label(state);
    table.draw().catch(showError);
    if (heatmapChanged(before, state)) heatmap.firstPage(); // the heat map shows the table's takes, from its first page
  }
  const progress = shootProgress(shootId, life, table.draw, heatmap.draw, showError);

  main.replaceChildren(
    h("h1", {}, h("a", { href: "#/shoots" }, "Shoots"), " / ", title),
    h("div", { class: "controls", id: "shoot-actions" },
      h("a", { class: "button primary", id: "review-queue", href: `#/shoot/${shootId}/review` }, "review queue"),
      exports.csv, exports.json,
      manageControls(shoot, who, (renamed) => { title.textContent = renamed.name; })),
    modelPanel,
    importPanel(shootId, progress.restart),
    progress.panel,
    tableArea, heatmap.el);
  tableArea.replaceChildren(filterBar(state, apply, allColumnsToggle(tableArea)), tableBox);
  await table.draw();
  await progress.poll();
  main.dataset.ready = "1";
  heatmap.show();
}

/** The summary downloads: they hold what the table lists (its filters and order), and say so
 * when filtered; `label(state)` writes their links and names for the table's state. */
function exportLinks(shootId) {
  const links = {
    csv: h("a", { class: "download", id: "export-csv", download: "" }),
    json: h("a", { class: "download", id: "export-json", download: "" }),
  };
  const label = (state) => {
    for (const [kind, link] of Object.entries(links)) {
      link.href = api.summaryUrl(shootId, kind, exportQuery(state));
      link.textContent = `${isFiltered(state) ? "filtered " : ""}summary ${kind.toUpperCase()}`;
      link.title = isFiltered(state) ? "the takes that pass the table's filters, in its order" : "every take, in the table's order";
    }
  };
  return { ...links, label };
}

/** The analysis progress bar. It polls while anything is queued or running (redrawing the
 * table), and when it all finishes redraws table and heat map; `life` holds the view's
 * liveness and the poll's timer. */
function shootProgress(shootId, life, drawTable, drawHeatmap, showError) {
  const bar = h("progress", { id: "shoot-progress", max: 1, value: 0 });
  const text = h("span", { id: "shoot-progress-text" });
  const panel = h("div", { class: "panel", id: "progress-panel" }, "analysis ", bar, " ", text);
  let wasRunning = false;
  const poll = async () => {
    const progress = await api.shootProgress(shootId);
    if (!life.alive) return;
    const summary = progressSummary(progress);
    bar.value = summary.share;
    text.textContent = summary.text;
    panel.dataset.finished = progress.finished ? "1" : "0";
    if (!progress.finished) {
      wasRunning = true;
      await drawTable();
      life.timer = setTimeout(() => poll().catch(showError), POLL_MS);
    } else if (wasRunning) {
      wasRunning = false;
      await Promise.all([drawTable(), drawHeatmap()]);
    }
  };
  const restart = () => { clearTimeout(life.timer); wasRunning = true; poll().catch(showError); };
  return { panel, poll, restart };
}

export async function reviewQueueView(main, shootId, onTeardown) {
  // The server records each review as the signed-in user: there is no name to type.
  const [shoot, who] = await Promise.all([api.getShoot(shootId), me().catch(() => null)]);
  const notes = h("textarea", { id: "queue-notes", placeholder: "notes (optional, saved with the next decision)", "aria-label": "notes" });
  const card = h("div", { class: "panel", id: "queue-card" });
  const message = h("p", { id: "queue-message", class: "muted" });
  const help = h("p", { class: "muted", id: "keys-help" },
    "Keys: A approve · F needs fix · R reject (each saves, with the notes, and moves to the next take) · S skip · O open the take · ? shows or hides this line · keys typed in the notes are text");
  let current = null;
  let busy = false;

  const show = async (after) => {
    const next = await api.nextForReview(shootId, after);
    current = next.take;
    if (!current) {
      card.replaceChildren(h("p", { id: "queue-done" }, "Nothing left to review in this shoot."));
      card.dataset.take = "";
      return;
    }
    const t = current;
    const score = h("span", { class: "score big", id: "queue-score" }, fmt(t.score, 1));
    score.style.color = scoreColor(t.score);
    const decide = (decision, label, key) => h("button", { "data-decision": decision, onclick: () => record(decision) }, `${label} (${key})`);
    card.dataset.take = t.take_id;
    card.replaceChildren(
      h("div", { class: "row" },
        h("img", { class: "thumb big", src: api.thumbnailUrl(t.take_id, t.run_id), alt: "" }),
        h("div", { class: "col" },
          h("h2", { id: "queue-name" }, t.name), h("p", {}, "QA score ", score, ` · ${next.remaining} left to review`),
          h("table", { class: "compact" }, h("tbody", {}, TAKE_COLUMNS.filter((c) => !["name", "score", "review_status", "reviewer"].includes(c.key))
            .map((c) => h("tr", {}, h("th", {}, c.label), h("td", {}, formatCell(c.key, t)))))),
          h("p", {}, h("a", { href: api.takeLink(t.take_id, t.run_id), id: "queue-open" }, "open in the take view")))),
      h("div", { class: "controls" }, decide("approved", "approve", "A"), decide("needs_fix", "needs fix", "F"), decide("rejected", "reject", "R"),
        h("button", { onclick: () => skip() }, "skip (S)")));
  };
  const record = async (decision) => {
    if (!current || busy) return;
    busy = true;
    try {
      await api.addReview(current.take_id, { status: decision, notes: notes.value });
      notes.value = "";
      message.textContent = `${current.name}: ${REVIEW[decision]}`; message.className = "muted";
      await show();
    } catch (e) { message.textContent = e.message; message.className = "error"; } finally { busy = false; }
  };
  const skip = async () => { if (current && !busy) await show(current.take_id); };
  const onKey = (e) => {
    if (e.target instanceof HTMLInputElement || e.target instanceof HTMLTextAreaElement || e.ctrlKey || e.metaKey || e.altKey) return;
    const decision = decisionForKey(e.key);
    if (decision) { e.preventDefault(); record(decision); }
    else if (e.key === "s" || e.key === "S") { e.preventDefault(); skip(); }
    else if ((e.key === "o" || e.key === "O") && current) location.hash = api.takeLink(current.take_id, current.run_id);
    else if (e.key === "?") help.hidden = !help.hidden;
  };
  document.addEventListener("keydown", onKey);
  onTeardown(() => document.removeEventListener("keydown", onKey));
  main.replaceChildren(h("h1", {}, h("a", { href: "#/shoots" }, "Shoots"), " / ", h("a", { href: api.shootLink(shootId) }, shoot.name), " / review queue"),
    ...(who ? [h("p", { class: "muted", id: "queue-who" }, `Reviews are recorded as ${who.name}.`)] : []), help, card, notes, message);
  await show();
  main.dataset.ready = "1";
}
