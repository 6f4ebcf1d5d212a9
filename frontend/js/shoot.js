// Shoots: the list (#/shoots), one shoot's take table with import, live progress, export and
// the violations heat map (#/shoot/ID), and its review queue (#/shoot/ID/review).
// The table is sorted, filtered and paged on the server; its state lives in the URL.
import * as api from "./api.js";
import { me } from "./account-api.js";
import { activatable, badge, h, REVIEW } from "./dom.js";
import { loadPlotly, untabbableModebar } from "./plotly.js";
import { fmt } from "./format.js";
import { limitsModelPanel } from "./shoot-limits.js";
import {
  decisionForKey, deleteConfirmed, exportQuery, formatCell, HEATMAP_COLORSCALE, HEATMAP_SIZES, HEATMAP_TICK_ANGLE, heatmapChanged, heatmapFigure,
  heatmapKeyGradient, heatmapPage, heatmapPager, heatmapQuery, importLines, isFiltered, nextSort, pageInfo, progressSummary, scoreColor,
  scoreRangeProblem, shootControls, TAKE_COLUMNS, tableState, takesQuery, viewQuery,
} from "./shoot-format.js";

const POLL_MS = 1000;
const ALL_COLUMNS_KEY = "mocapqa-shoot-all-columns"; // the take table's "all columns" choice, kept in the browser

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

/** The take table's filters. Every field has a visible label (a typed number says nothing by
 * itself); a score range that can match no take is said at once beside the fields. The
 * "all columns" toggle shows the columns a narrow window hides (the table then scrolls in
 * its box). */
function filterBar(state, apply, allColumns) {
  const select = (key, label, options) => h("label", {}, `${label} `, h("select", { id: `shoot-${key}`, onchange: (e) => apply({ [key]: e.target.value }) },
    options.map(([v, text]) => h("option", { value: v, selected: String(state[key]) === v }, text))));
  const fields = {};
  const input = (key, attrs, onInput = () => {}) => {
    const el = h("input", { id: `shoot-${key}`, value: state[key], ...attrs });
    let timer = null;
    el.addEventListener("input", () => { onInput(); clearTimeout(timer); timer = setTimeout(() => apply({ [key]: el.value }), 350); });
    fields[key] = el;
    return el;
  };
  const scoreMessage = h("span", { id: "shoot-score-message", role: "alert" });
  const checkScores = () => {
    const problem = scoreRangeProblem({ min_score: fields.min_score.value, max_score: fields.max_score.value });
    for (const key of ["min_score", "max_score"]) fields[key].setAttribute("aria-invalid", String(!!problem && problem.fields.includes(key)));
    scoreMessage.textContent = problem ? problem.text : "";
    scoreMessage.className = problem ? "error" : "";
  };
  const labelled = (label, el) => h("label", { for: el.id }, `${label} `, el);
  const bar = h("div", { class: "controls shoot-filters" },
    input("search", { type: "search", "aria-label": "search name", placeholder: "search name" }),
    select("status", "run", [["", "any"], ["queued", "queued"], ["running", "running"], ["done", "done"], ["failed", "failed"]]),
    select("review_status", "review", [["", "any"], ...Object.entries(REVIEW)]),
    select("has_findings", "findings", [["", "any"], ["true", "some"], ["false", "none"]]),
    labelled("rig", input("rig", { class: "short" })),
    labelled("min score", input("min_score", { type: "number", min: 0, max: 100, step: "any", placeholder: "0", class: "short" }, () => checkScores())),
    labelled("max score", input("max_score", { type: "number", min: 0, max: 100, step: "any", placeholder: "100", class: "short" }, () => checkScores())),
    scoreMessage, allColumns);
  checkScores();
  return bar;
}

/** The "all columns" toggle (shown only where the window hides columns): a pressed button that
 * marks the table area, the choice kept in the browser. */
function allColumnsToggle(area) {
  const button = h("button", { type: "button", id: "shoot-all-columns", class: "columns-toggle", "aria-pressed": "false",
    title: "show the duration, rig, spins, worst joint, filter, missing and reviewer columns too (the table scrolls sideways in its box)" }, "all columns");
  const set = (on) => {
    button.setAttribute("aria-pressed", String(on));
    area.classList.toggle("all-columns", on);
  };
  let stored = null;
  try { stored = localStorage.getItem(ALL_COLUMNS_KEY); } catch { /* storage refused: not kept */ }
  set(stored === "1");
  button.addEventListener("click", () => {
    const on = button.getAttribute("aria-pressed") !== "true";
    set(on);
    try { localStorage.setItem(ALL_COLUMNS_KEY, on ? "1" : "0"); } catch { /* storage refused: not kept */ }
  });
  return button;
}

/** A selector finding again, after a redraw of `box`, the element of it that has the focus:
 * by a header's column, a row's take or the element's id (null when the focus is elsewhere). */
function focusedIn(box) {
  const el = document.activeElement;
  if (!el || el === box || !box.contains(el)) return null;
  if (el.dataset.sort) return `th[data-sort="${CSS.escape(el.dataset.sort)}"]`;
  if (el.dataset.take) return `tr[data-take="${CSS.escape(el.dataset.take)}"]`;
  return el.id ? `#${CSS.escape(el.id)}` : null;
}

function takeTable(page, state, apply) {
  const header = TAKE_COLUMNS.map((c) => {
    const sorted = state.sort === c.key;
    const th = h("th", { class: `sortable${c.narrow ? " narrow-hide" : ""}`, "data-sort": c.key, "aria-sort": sorted ? (state.order === "asc" ? "ascending" : "descending") : "none", title: c.title || null },
      c.label, sorted ? (state.order === "asc" ? " ▲" : " ▼") : "");
    // From the state when clicked, not when drawn: two clicks before the answer toggle twice.
    return activatable(th, () => apply((now) => nextSort(now, c.key)));
  });
  const rows = page.items.map((t) => activatable(h("tr", { class: "clickable", "data-take": t.take_id, "aria-label": `open ${t.name}` },
    h("td", { class: "thumb-cell" }, t.status === "done" ? h("img", { class: "thumb", src: api.thumbnailUrl(t.take_id, t.run_id), alt: "" }) : null),
    TAKE_COLUMNS.map((c) => {
      const text = formatCell(c.key, t);
      const cell = c.key === "status" ? badge(text) : c.key === "review_status" ? badge(text, t.review_status)
        : c.key === "score" ? h("span", { class: "score", style: null, "data-score": t.score ?? "" }, text) : text;
      const td = h("td", { class: `${c.key === "name" ? "name" : ""}${c.narrow ? " narrow-hide" : ""}` || null }, cell);
      if (c.key === "score") td.firstChild.style.color = scoreColor(t.score);
      return td;
    })), () => { location.hash = api.takeLink(t.take_id, t.run_id); }));
  // The order in words too: a narrow window hides some sorted columns' headers.
  const by = TAKE_COLUMNS.find((c) => c.key === state.sort);
  const caption = h("caption", { id: "shoot-sort", class: "muted" }, by ? `sorted by ${by.label} ${state.order === "asc" ? "▲" : "▼"}` : "");
  return h("div", { class: "table-scroll" }, h("table", { id: "shoot-takes" }, caption,
    h("thead", {}, h("tr", {}, h("th", {}, ""), header)), h("tbody", {}, rows)));
}

export async function shootView(main, shootId, params, onTeardown) {
  let state = tableState(params);
  const [shoot, who] = await Promise.all([api.getShoot(shootId), me().catch(() => null)]);
  // Runs queued from the model panel show their progress and redraw the table as they finish.
  const modelPanel = await limitsModelPanel(shoot, who, () => restartPolling());
  const title = h("span", { id: "shoot-title" }, shoot.name);
  const progressBar = h("progress", { id: "shoot-progress", max: 1, value: 0 });
  const progressText = h("span", { id: "shoot-progress-text" });
  const tableBox = h("div", { id: "take-table-box" });
  const tableArea = h("div", { id: "shoot-table-area" });
  const heatmap = h("div", { id: "shoot-heatmap", class: "panel" });
  let timer = null;
  let alive = true;
  onTeardown(() => { alive = false; clearTimeout(timer); });

  let drawn = 0; // the latest table request: an older answer arriving late is dropped
  const drawTable = async () => {
    const request = ++drawn;
    const problem = scoreRangeProblem(state);
    if (problem) { // no take can match: no request, and no silent "0–0 of 0" (the filter bar says why)
      tableBox.replaceChildren(h("p", { class: "muted", id: "shoot-table-empty" }, "No takes listed: the score range above matches none."));
      tableArea.dataset.query = takesQuery(state);
      return;
    }
    const page = await api.shootTakes(shootId, takesQuery(state));
    if (!alive || request !== drawn) return;
    const info = pageInfo(state.offset, state.limit, page.total);
    const move = (offset) => h("button", { disabled: offset == null, onclick: () => apply({ offset }) });
    const previous = move(info.previous); previous.append("‹ previous"); previous.id = "page-previous";
    const next = move(info.next); next.append("next ›"); next.id = "page-next";
    // The filter bar stays (a poll must not take the focus from the search field); the table
    // and pager are redrawn, and what had the focus in them keeps it: the same header, the
    // same take's row (polled every second while takes are analysed), the same pager button.
    const focused = focusedIn(tableBox);
    tableBox.replaceChildren(takeTable(page, state, apply),
      h("div", { class: "controls" }, previous, h("span", { id: "page-info" }, info.text), next));
    if (focused) {
      const again = tableBox.querySelector(focused);
      if (again && !again.disabled) again.focus({ preventScroll: true });
    }
    tableArea.dataset.query = takesQuery(state);
  };
  // The downloads hold what the table lists (its filters and order), and say so when filtered.
  const exportLinks = {
    csv: h("a", { class: "download", id: "export-csv", download: "" }),
    json: h("a", { class: "download", id: "export-json", download: "" }),
  };
  const labelExports = () => {
    for (const [kind, link] of Object.entries(exportLinks)) {
      link.href = api.summaryUrl(shootId, kind, exportQuery(state));
      link.textContent = `${isFiltered(state) ? "filtered " : ""}summary ${kind.toUpperCase()}`;
      link.title = isFiltered(state) ? "the takes that pass the table's filters, in its order" : "every take, in the table's order";
    }
  };
  labelExports();
  function apply(change) {
    const patch = typeof change === "function" ? change(state) : change;
    const resetsPage = !("offset" in patch);
    const before = state;
    state = { ...state, ...patch, ...(resetsPage ? { offset: 0 } : {}) };
    history.replaceState(null, "", api.shootLink(shootId, viewQuery(state)));
    labelExports();
    drawTable().catch(showError);
    if (heatmapChanged(before, state)) { // the heat map shows the table's takes, from its first page
      heat = heatmapPage(0, heat.limit);
      drawHeatmap().catch(showHeatmapError);
    }
  }
  const showError = (e) => tableArea.prepend(h("p", { class: "error" }, e.message));

  // The heat map shows the take table's takes (its filters, sort and order) `heat.limit` at a
  // time; the chart scrolls inside its box, and the pager keeps its place across polls. A
  // redraw started later wins over one still waiting for its answer (typing in the search).
  let heat = heatmapPage(0, 200);
  let heatDrawn = 0;
  const drawHeatmap = async () => {
    const ticket = ++heatDrawn;
    const shown = state;
    const problem = scoreRangeProblem(shown);
    if (problem) { // as the table: no request, the reason in words
      heatmap.replaceChildren(h("h2", {}, "Joint limits"), h("p", { class: "muted", id: "heatmap-empty" }, `No take matches the table's filters: ${problem.text}.`));
      return;
    }
    const [Plotly, first] = await Promise.all([loadPlotly(), api.shootHeatmap(shootId, heatmapQuery(heat, shown))]);
    let data = first;
    const safe = heatmapPage(heat.offset, heat.limit, data.total);
    if (safe.offset !== heat.offset) { // the shoot shrank under the page: show its last page
      heat = safe;
      data = await api.shootHeatmap(shootId, heatmapQuery(heat, shown));
    }
    if (!alive || ticket !== heatDrawn) return;
    heatmap.dataset.query = heatmapQuery(heat, shown);
    const title = h("h2", {}, "Share of frames outside the joint limits (joint × take, in the table's order and filters)");
    if (!data.total) {
      const why = isFiltered(shown) ? "No take matches the table's filters." : "No joint-limit results yet.";
      heatmap.replaceChildren(h("h2", {}, "Joint limits"), h("p", { class: "muted", id: "heatmap-empty" }, why));
      return;
    }
    const pager = heatmapPager(heat, data.total);
    const go = (offset) => { heat = heatmapPage(offset, heat.limit, data.total); drawHeatmap().catch(showHeatmapError); };
    const previous = h("button", { type: "button", id: "heatmap-previous", disabled: pager.previous == null, onclick: () => go(pager.previous) }, "‹ previous");
    const next = h("button", { type: "button", id: "heatmap-next", disabled: pager.next == null, onclick: () => go(pager.next) }, "next ›");
    const size = h("select", { id: "heatmap-size", "aria-label": "takes per heat map page", onchange: (e) => {
      heat = heatmapPage(heat.offset, e.target.value, data.total); drawHeatmap().catch(showHeatmapError);
    } }, HEATMAP_SIZES.map((n) => h("option", { value: n, selected: n === heat.limit }, `${n} takes a page`)));
    const controls = h("div", { class: "controls", id: "heatmap-pager" }, previous, h("span", { id: "heatmap-page", "aria-live": "polite" }, pager.text), next, size);
    if (!data.joints.length) {
      heatmap.replaceChildren(title, controls, h("p", { class: "muted", id: "heatmap-empty" }, "No joint outside its limits in these takes."));
      return;
    }
    const figure = heatmapFigure(data, heat.offset);
    const chart = h("div", { id: "heatmap-chart", "data-offset": heat.offset });
    chart.style.minWidth = `${figure.minWidth}px`; // every joint column keeps its room: the box scrolls sideways instead
    // The colour key stays in view at the top of the scrolling box (the chart's own colour bar
    // would scroll away with a tall page); the joints are labelled above and below the cells.
    const bar = h("span", { class: "heatmap-key-bar" });
    bar.style.background = heatmapKeyGradient();
    const key = h("div", { class: "heatmap-key", id: "heatmap-key" }, "share of frames outside the limits: ",
      h("span", {}, "0 %"), bar, h("span", { id: "heatmap-key-max" }, `${fmt(figure.zmax, 1)} %`));
    heatmap.replaceChildren(title, controls, h("div", { class: "heatmap-scroll", id: "heatmap-scroll", tabindex: "0", "aria-label": "heat map, scrolls" }, key, chart));
    const joints = { ...figure.xaxis, tickangle: HEATMAP_TICK_ANGLE, automargin: true };
    await Plotly.newPlot(chart, [{
      type: "heatmap", x: figure.x, y: figure.y, z: figure.z, text: figure.text,
      colorscale: HEATMAP_COLORSCALE, zmin: 0, zmax: figure.zmax, hoverongaps: false, showscale: false,
      hovertemplate: "%{text}<br>%{x}: %{z:.1f} % of frames outside<extra></extra>",
    }, { // no data to draw: it only gives the joints' axis above the cells its categories
      type: "scatter", mode: "markers", x: figure.x, y: figure.x.map(() => figure.y[0]), xaxis: "x2",
      marker: { opacity: 0 }, hoverinfo: "skip", showlegend: false,
    }], {
      height: figure.height, margin: figure.margin,
      yaxis: { ...figure.yaxis, automargin: true },
      xaxis: { ...joints, side: "bottom" },
      xaxis2: { ...joints, side: "top", overlaying: "x", matches: "x" },
    }, { responsive: true, displaylogo: false });
    untabbableModebar(chart);
  };
  const showHeatmapError = (e) => heatmap.replaceChildren(h("p", { class: "error" }, e.message));

  // Poll while anything is queued or running; when it all finishes, redraw table and heat map.
  let wasRunning = false;
  const poll = async () => {
    const progress = await api.shootProgress(shootId);
    if (!alive) return;
    const summary = progressSummary(progress);
    progressBar.value = summary.share;
    progressText.textContent = summary.text;
    progressPanel.dataset.finished = progress.finished ? "1" : "0";
    if (!progress.finished) {
      wasRunning = true;
      await drawTable();
      timer = setTimeout(() => poll().catch(showError), POLL_MS);
    } else if (wasRunning) {
      wasRunning = false;
      await Promise.all([drawTable(), drawHeatmap()]);
    }
  };
  const restartPolling = () => { clearTimeout(timer); wasRunning = true; poll().catch(showError); };
  const progressPanel = h("div", { class: "panel", id: "progress-panel" }, "analysis ", progressBar, " ", progressText);

  main.replaceChildren(
    h("h1", {}, h("a", { href: "#/shoots" }, "Shoots"), " / ", title),
    h("div", { class: "controls", id: "shoot-actions" },
      h("a", { class: "button primary", id: "review-queue", href: `#/shoot/${shootId}/review` }, "review queue"),
      exportLinks.csv, exportLinks.json,
      manageControls(shoot, who, (renamed) => { title.textContent = renamed.name; })),
    modelPanel,
    importPanel(shootId, restartPolling),
    progressPanel,
    tableArea, heatmap);
  tableArea.replaceChildren(filterBar(state, apply, allColumnsToggle(tableArea)), tableBox);
  await drawTable();
  await poll();
  main.dataset.ready = "1";
  drawHeatmap().catch(showHeatmapError);
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
