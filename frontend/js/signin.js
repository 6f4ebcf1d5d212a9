// The sign-in page: name and password, or the message of a refused one-time link.
import { h, signIn } from "./account-api.js";

const main = document.getElementById("main");
const name = h("input", { id: "signin-name", autocomplete: "username", placeholder: "user name", required: true });
const password = h("input", { id: "signin-password", type: "password", autocomplete: "current-password", placeholder: "password", required: true });
const message = h("p", { id: "signin-message", class: "error" });
if (new URLSearchParams(location.search).get("link") === "refused") {
  message.textContent = "That sign-in link was used already or has expired: restart `mocapqa serve` for a new one, or sign in.";
}
const form = h("form", { class: "signin", id: "signin-form", onsubmit: async (e) => {
  e.preventDefault();
  try { await signIn(name.value, password.value); location.assign("/"); } catch (err) { message.textContent = err.message; }
} }, h("h1", {}, "Sign in"), name, password, h("button", { class: "primary", id: "signin-submit", type: "submit" }, "sign in"), message);
main.replaceChildren(form);
