// The router: #/ (takes), #/upload, #/shoots, #/shoot/ID[/review], #/take/ID?run=RID&frame=F, #/compare. One module per view,
// each loaded when its route is first opened, with every module it may load preloaded at once.
import { h, preloadModulesOf } from "./dom.js";
import { parseRoute } from "./route.js";
import "./prefetch.js"; // the take view's first requests, started before the first route (see there)

const main = document.getElementById("main");
// Shown while a route loads for longer than a blink: the previous page stays until the new one
// is drawn, and on a slow network it would otherwise look like nothing happened.
const loading = h("div", { id: "route-loading", role: "status", "aria-live": "polite", hidden: true }, "loading…");
document.body.append(loading);
let loadingTimer = null;
let teardowns = [];
let routed = 0; // routes opened so far: a view whose module arrives after a newer route is not shown

/** A view's module: what it may load is preloaded first (the server lists it: dom.js). */
function viewModule(file, load) {
  preloadModulesOf(new URL(file, import.meta.url).pathname);
  return load();
}
const VIEWS = {
  take: () => viewModule("./take.js", () => import("./take.js")),
  upload: () => viewModule("./upload.js", () => import("./upload.js")),
  compare: () => viewModule("./compare.js", () => import("./compare.js")),
  shoot: () => viewModule("./shoot.js", () => import("./shoot.js")),
  list: () => viewModule("./list.js", () => import("./list.js")),
};

async function open(parts, params, current) {
  const addTeardown = (t) => teardowns.push(t);
  const name = ["take", "upload", "compare"].includes(parts[0]) ? parts[0] : parts[0] === "shoots" || parts[0] === "shoot" ? "shoot" : "list";
  const view = await VIEWS[name]();
  if (current !== routed) return;
  if (parts[0] === "take") return view.takeView(main, parts[1], params, addTeardown);
  if (parts[0] === "upload") return view.uploadView(main);
  if (parts[0] === "compare") return view.compareView(main, params, addTeardown);
  if (parts[0] === "shoots") return view.shootsView(main);
  if (parts[0] === "shoot" && parts[2] === "review") return view.reviewQueueView(main, parts[1], addTeardown);
  if (parts[0] === "shoot") return view.shootView(main, parts[1], params, addTeardown);
  return view.listView(main, params, route).then(() => { main.dataset.ready = "1"; });
}

function route() {
  for (const teardown of teardowns) teardown();
  teardowns = [];
  delete main.dataset.ready;
  const { parts, params } = parseRoute(location.hash);
  const mine = ++routed;
  clearTimeout(loadingTimer);
  loadingTimer = setTimeout(() => { if (mine === routed) loading.hidden = false; }, 300);
  main.setAttribute("aria-busy", "true");
  const done = () => {
    if (mine !== routed) return;
    clearTimeout(loadingTimer);
    loading.hidden = true;
    main.removeAttribute("aria-busy");
  };
  open(parts, params, mine).then(done, (e) => { done(); main.replaceChildren(h("p", { class: "error" }, e.message)); });
}
window.addEventListener("hashchange", route);
route();
