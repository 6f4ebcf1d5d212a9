// Everyone: my personal API tokens (admins: everyone's); make one (shown once), revoke.
import { createToken, h, listTokens, me, revokeToken, when } from "./account-api.js";

const main = document.getElementById("main");

async function show(secret = null) {
  let who, tokens;
  try { who = await me(); tokens = await listTokens(who.can.includes("manage_users")); } catch (e) { main.replaceChildren(h("p", { class: "error" }, e.message)); return; }
  const message = h("p", { id: "tokens-message" });
  const rows = tokens.map((t) => h("tr", { "data-token": t.id },
    h("td", {}, t.id), h("td", {}, t.user), h("td", {}, t.name), h("td", {}, when(t.created_at)), h("td", {}, when(t.expires_at)),
    h("td", {}, when(t.last_used_at)),
    h("td", {}, t.revoked_at ? `revoked ${when(t.revoked_at)}` : h("button", { onclick: () => revokeToken(t.id).then(() => show(), (e) => { message.textContent = e.message; }) }, "revoke"))));
  const name = h("input", { id: "token-name", placeholder: "what it is for" });
  const days = h("input", { id: "token-days", type: "number", min: 1, max: 3650, value: 90 });
  const create = h("button", { class: "primary", id: "token-create", onclick: () => createToken(name.value, Number(days.value)).then((t) => show(t), (e) => { message.textContent = e.message; }) }, "create token");
  const shown = secret
    ? h("div", { class: "panel" }, h("p", {}, "Your new token, shown this once (send it as Authorization: Bearer TOKEN):"), h("p", { class: "secret", id: "token-secret" }, secret.token))
    : null;
  main.replaceChildren(h("h1", {}, "Personal API tokens"), shown,
    h("div", { class: "controls" }, name, "expires in (days)", days, create), message,
    h("table", { id: "tokens" }, h("thead", {}, h("tr", {}, ["id", "user", "name", "created", "expires", "last used", ""].map((c) => h("th", {}, c)))), h("tbody", {}, rows)));
}

show();
