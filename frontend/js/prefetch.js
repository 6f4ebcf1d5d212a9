// The take view's first requests, started as the page starts. index.html loads this module with
// its own <script async> ahead of the others and preloads its few imports first, so it runs
// while the rest of the dashboard is still loading: when the page opens on a take
// (#/take/ID?run=RID) it preloads the take view's modules and asks for the take and, with a run
// in the address, for the run's result and light first frames, ahead of those modules; api.js
// hands each started response to the view's own request of the same URL. app.js imports it
// too, so it has always run before the first view asks.
import * as api from "./api.js";
import { preloadModulesOf } from "./dom.js";
import { parseRoute } from "./route.js";

const { parts, params } = parseRoute(location.hash);
if (parts[0] === "take" && parts[1]) {
  api.prefetchTake(parts[1], params.get("run"));
  preloadModulesOf(new URL("./take.js", import.meta.url).pathname);
}
// Started responses serve the first view only: after any change of view they are dropped (this
// listener is added before app.js's router's, so it runs first).
window.addEventListener("hashchange", api.dropPrefetched);
