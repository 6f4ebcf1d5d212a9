// The take list: rows open with a click or, focused, with Enter. No charts: Plotly is not loaded.
import * as api from "./api.js";
import { activatable, badge, h, REVIEW } from "./dom.js";
import { fmt } from "./format.js";
import { dropZone, uploader } from "./upload.js";

export async function listView(main, params, refresh) {
  const status = params.get("status") || "";
  const review = params.get("review") || "";
  const page = await api.listTakes({ status, review_status: review, limit: 200 });
  const select = (name, value, options) => h("select", { id: `filter-${name}`, "aria-label": name, onchange: (e) => {
    const next = new URLSearchParams(params); next.set(name, e.target.value); location.hash = `#/?${next}`; } },
    options.map(([v, label]) => h("option", { value: v, selected: v === value }, label)));
  const uploadStatus = h("div", { id: "upload-area" });
  const rows = page.items.map((t) => {
    const remove = h("button", { class: "small", "aria-label": `delete ${t.name}` }, "delete");
    const stop = (e) => e.stopPropagation();
    remove.addEventListener("keydown", stop);
    remove.addEventListener("click", async (e) => {
      e.stopPropagation();
      if (confirm(`Delete ${t.name}?`)) { await api.deleteTake(t.id); refresh(); }
    });
    return activatable(h("tr", { class: "clickable", "data-take": t.id, "data-owner": t.owner_id ?? "", "aria-label": `open ${t.name}` },
      h("td", { class: "thumb-cell" }, h("img", { class: "thumb", src: api.thumbnailUrl(t.id, t.latest_run_id), alt: "" })),
      h("td", { class: "name" }, t.name), h("td", { class: "narrow-hide" }, t.format), h("td", {}, `${t.n_frames} @ ${fmt(t.fps, 0)} fps`),
      h("td", { class: "narrow-hide" }, t.n_joints), h("td", {}, badge(t.status || "none")), h("td", {}, badge(REVIEW[t.review_status], t.review_status)),
      h("td", {}, t.n_findings ?? "–"), h("td", {}, remove)), () => { location.hash = api.takeLink(t.id); });
  });
  main.replaceChildren(
    h("h1", {}, `Takes (${page.total})`),
    dropZone(async (files) => { await uploader(uploadStatus)(files); }), uploadStatus,
    h("div", { class: "controls" }, "Run status ", select("status", status, [["", "any"], ["queued", "queued"], ["running", "running"], ["done", "done"], ["failed", "failed"]]),
      "Review ", select("review", review, [["", "any"], ...Object.entries(REVIEW)])),
    h("table", { id: "take-list" }, h("thead", {}, h("tr", {}, ["", "name", "format", "frames", "joints/points", "run", "review", "findings", ""].map((c, k) =>
      h("th", { class: k === 2 || k === 4 ? "narrow-hide" : null }, c)))),
    h("tbody", {}, rows)),
  );
}
