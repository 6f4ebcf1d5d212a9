// The one frame of the account pages (sign-in, users, tokens, audit): the stylesheets, the
// header with the account menu's slot and the main area, then the page's own module. A page's
// HTML holds only its title and this script, naming the page:
//   <script type="module" src="/static/js/account-page.js?page=users"></script>
// (a module from the page's own origin: the Content-Security-Policy allows no inline script).
import { h } from "./dom.js";

/** The account pages: whether each shows the account menu (the sign-in page has no one to show). */
export const PAGES = { signin: { menu: false }, users: { menu: true }, tokens: { menu: true }, audit: { menu: true } };

const page = new URL(import.meta.url).searchParams.get("page");
if (!Object.hasOwn(PAGES, page)) throw new Error(`account-page.js: unknown page ${page}`);
document.head.append(
  h("link", { rel: "icon", href: "data:," }),
  h("link", { rel: "stylesheet", href: "/static/css/app.css" }),
  h("link", { rel: "stylesheet", href: "/static/css/account.css" }));
document.body.replaceChildren(
  h("header", { class: "top" }, h("a", { class: "brand", href: "/" }, "mocapqa"), h("nav", {}, h("a", { href: "/" }, "Takes")),
    h("span", { id: "account", class: "account" })),
  h("main", { id: "main" }, h("p", { class: "muted" }, "Loading…")));
await import(`./${page}.js`);
if (PAGES[page].menu) await import("./account-menu.js");
