// Admins: every user, their role and state; add a user, change a role, disable.
import { addUser, changeUser, h, listUsers, when } from "./account-api.js";

const main = document.getElementById("main");
const ROLES = ["viewer", "reviewer", "admin"];

async function show(note = "") {
  let users;
  try { users = await listUsers(); } catch (e) { main.replaceChildren(h("p", { class: "error" }, e.message)); return; }
  const message = h("p", { id: "users-message", class: note ? "muted" : "" }, note);
  const fail = (e) => { message.textContent = e.message; message.className = "error"; };
  const rows = users.map((u) => h("tr", { "data-user": u.name },
    h("td", {}, u.name),
    h("td", {}, h("select", { class: "user-role", onchange: (e) => changeUser(u.name, { role: e.target.value }).then(() => show(`${u.name} is now ${e.target.value}`), fail) },
      ROLES.map((r) => h("option", { value: r, selected: r === u.role }, r)))),
    h("td", {}, u.disabled ? "disabled" : "enabled"), h("td", {}, u.has_password ? "password" : "tokens only"), h("td", {}, when(u.created_at)),
    h("td", {}, u.disabled ? "" : h("button", { onclick: () => changeUser(u.name, { disabled: true }).then(() => show(`${u.name} disabled`), fail) }, "disable"))));
  const name = h("input", { id: "new-user-name", placeholder: "name" });
  const role = h("select", { id: "new-user-role" }, ROLES.map((r) => h("option", { value: r, selected: r === "reviewer" }, r)));
  const password = h("input", { id: "new-user-password", type: "password", placeholder: "password (none: tokens only)", autocomplete: "new-password" });
  const add = h("button", { class: "primary", id: "new-user-add", onclick: () => addUser({ name: name.value, role: role.value, password: password.value || null }).then(() => show(`${name.value} added`), fail) }, "add user");
  main.replaceChildren(h("h1", {}, "Users"),
    h("table", { id: "users" }, h("thead", {}, h("tr", {}, ["name", "role", "state", "sign-in", "created", ""].map((c) => h("th", {}, c)))), h("tbody", {}, rows)),
    h("div", { class: "controls" }, name, role, password, add), message);
}

show();
