// The router: #/ (takes), #/upload, #/shoots, #/shoot/ID[/review], #/take/ID?run=RID&frame=F, #/compare. One module per view.
import { h } from "./dom.js";
import { compareView } from "./compare.js";
import { listView } from "./list.js";
import { reviewQueueView, shootsView, shootView } from "./shoot.js";
import { takeView } from "./take.js";
import { uploadView } from "./upload.js";

const main = document.getElementById("main");
let teardowns = [];

function route() {
  for (const teardown of teardowns) teardown();
  teardowns = [];
  delete main.dataset.ready;
  const [path, query] = location.hash.replace(/^#/, "").split("?");
  const params = new URLSearchParams(query || "");
  const parts = (path || "/").split("/").filter(Boolean);
  const view = parts[0] === "take" ? takeView(main, parts[1], params, (t) => teardowns.push(t))
    : parts[0] === "upload" ? uploadView(main)
    : parts[0] === "compare" ? compareView(main, params, (t) => teardowns.push(t))
    : parts[0] === "shoots" ? shootsView(main)
    : parts[0] === "shoot" && parts[2] === "review" ? reviewQueueView(main, parts[1], (t) => teardowns.push(t))
    : parts[0] === "shoot" ? shootView(main, parts[1], params, (t) => teardowns.push(t))
    : listView(main, params, route).then(() => { main.dataset.ready = "1"; });
  view.catch((e) => main.replaceChildren(h("p", { class: "error" }, e.message)));
}
window.addEventListener("hashchange", route);
route();
