// Header: who am I, links to the account pages my role may use, sign out. Marks the page with
// the actions my role may perform (html[data-can]), so css/account.css hides the other controls.
import { h, me, signOut } from "./account-api.js";

async function show() {
  const slot = document.getElementById("account");
  if (!slot) return;
  let who;
  try { who = await me(); } catch { return; } // 401: api.js opens the sign-in page
  document.documentElement.dataset.can = who.can.join(" ");
  document.documentElement.dataset.user = who.user_id ?? "";
  if (!who.can.includes("delete_any")) {
    // A reviewer deletes only takes they own.
    const rule = `tr[data-take]:not([data-owner="${who.user_id ?? "-"}"]) td:last-child button { display:none; }`;
    document.head.append(h("style", {}, rule));
  }
  const links = [h("a", { href: "/static/tokens.html", id: "nav-tokens" }, "Tokens")];
  if (who.can.includes("manage_users")) links.push(h("a", { href: "/static/users.html", id: "nav-users" }, "Users"));
  if (who.can.includes("read_audit")) links.push(h("a", { href: "/static/audit.html", id: "nav-audit" }, "Audit"));
  // Only a signed-in session can sign out (a token or the open mode has nothing to end).
  const out = who.via === "session"
    ? [h("button", { id: "sign-out", class: "link", onclick: async () => { await signOut(); location.assign("/static/signin.html"); } }, "sign out")]
    : [];
  slot.replaceChildren(...links, h("span", { id: "whoami" }, `${who.name} (${who.role})`), ...out);
}

show();
