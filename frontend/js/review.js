// The review panel: a decision with notes; saving updates the panel in place (the player, its
// frame and the camera stay as they are).
import * as api from "./api.js";
import { badge, h, REVIEW, toast } from "./dom.js";

export function reviewPanel(take) {
  const panel = h("div", { class: "panel", id: "review-panel" });
  const current = take.reviews[0];
  const status = h("select", { id: "review-status", "aria-label": "review decision" }, Object.entries(REVIEW).map(([v, l]) => h("option", { value: v, selected: v === (current ? current.status : "unreviewed") }, l)));
  const notes = h("textarea", { id: "review-notes", placeholder: "notes", "aria-label": "notes" });
  const message = h("span", { id: "review-message", class: "muted" });
  const history = h("ul", { id: "review-history" });
  const showHistory = (reviews) => history.replaceChildren(...reviews.map((r) => h("li", {}, `${new Date(r.created_at).toLocaleString()} · ${r.reviewer}: `, badge(REVIEW[r.status], r.status), r.notes ? ` — ${r.notes}` : "")));
  const save = h("button", { id: "review-save", class: "primary", onclick: async () => {
    try {
      // The reviewer is whoever is signed in.
      await api.addReview(take.id, { status: status.value, notes: notes.value });
      const fresh = await api.getTake(take.id);
      showHistory(fresh.reviews);
      message.textContent = "saved"; message.className = "muted";
      // A/F/R save from anywhere on the page: say what was recorded where it can be seen.
      toast(`review saved: ${REVIEW[status.value]}`);
    } catch (e) { message.textContent = e.message; message.className = "error"; toast(e.message); }
  } }, "save review");
  showHistory(take.reviews);
  /** Record a decision from the keyboard (A/F/R): set it and save. */
  panel.decide = (decision) => { status.value = decision; save.click(); };
  panel.append(h("h2", {}, "Review"), h("div", { class: "controls" }, status, save, message), notes, history);
  return panel;
}
