// Admins: the audit log, newest first, a page at a time (read only).
import { h, listAudit, when } from "./account-api.js";

const main = document.getElementById("main");
const PAGE = 100;

async function show(offset = 0) {
  let page;
  try { page = await listAudit(PAGE, offset); } catch (e) { main.replaceChildren(h("p", { class: "error" }, e.message)); return; }
  const rows = page.items.map((e) => h("tr", {}, h("td", {}, when(e.at)), h("td", {}, e.user_name ?? "–"), h("td", {}, e.action),
    h("td", {}, e.target), h("td", {}, e.detail), h("td", {}, e.client)));
  const older = offset + PAGE < page.total ? h("button", { id: "audit-older", onclick: () => show(offset + PAGE) }, "older") : null;
  const newer = offset > 0 ? h("button", { id: "audit-newer", onclick: () => show(Math.max(0, offset - PAGE)) }, "newer") : null;
  main.replaceChildren(h("h1", {}, `Audit log (${page.total})`),
    h("table", { id: "audit" }, h("thead", {}, h("tr", {}, ["when", "who", "action", "target", "detail", "from"].map((c) => h("th", {}, c)))), h("tbody", {}, rows)),
    h("div", { class: "controls" }, newer, older, `${offset + 1}–${offset + page.items.length} of ${page.total}`));
}

show();
