// Tiny DOM helpers shared by the views. Event handlers are attached with addEventListener
// (never inline attributes: the Content-Security-Policy forbids inline script).

export const h = (tag, attrs = {}, ...children) => {
  const el = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (k.startsWith("on")) el.addEventListener(k.slice(2), v);
    else if (v === true) el.setAttribute(k, "");
    else if (v !== false && v != null) el.setAttribute(k, v);
  }
  for (const c of children.flat()) if (c != null) el.append(c instanceof Node ? c : String(c));
  return el;
};

export const badge = (text, cls) => h("span", { class: `badge ${cls || text}` }, text);

export const REVIEW = { unreviewed: "unreviewed", approved: "approved", needs_fix: "needs fix", rejected: "rejected" };

/** Make a row or header act like a button: focusable, Enter/space activate it. */
export function activatable(el, action) {
  el.setAttribute("tabindex", "0");
  el.addEventListener("click", action);
  el.addEventListener("keydown", (e) => {
    if (e.key === "Enter" || (e.key === " " && e.target === el)) { e.preventDefault(); e.stopPropagation(); action(e); }
  });
  return el;
}

/** Fetch these modules now, all at once, rather than one level of imports after another. */
export function preloadModules(urls) {
  for (const href of urls) {
    if (!document.head.querySelector(`link[rel="modulepreload"][href="${href}"]`)) document.head.append(h("link", { rel: "modulepreload", href }));
  }
}

/** Preload a module loaded on demand and every module it may load (static imports and further
 * on-demand ones, Plotly aside), as the server listed them from the import graph in
 * `<meta name="modules-of" data-module="URL">` (backend/mocapqa/api/index_page.py). */
export function preloadModulesOf(url) {
  const meta = document.head.querySelector(`meta[name="modules-of"][data-module="${url}"]`);
  preloadModules(meta ? meta.content.split(" ").filter(Boolean) : [url]);
}

/** A short message at the bottom of the window, read out by screen readers, gone after a few
 * seconds: feedback for a key press whose result is not on screen (one at a time). */
export function toast(text, seconds = 3) {
  let el = document.getElementById("toast");
  if (!el) {
    el = h("div", { id: "toast", role: "status", "aria-live": "polite" });
    document.body.append(el);
  }
  el.textContent = text;
  el.hidden = false;
  clearTimeout(el.timer);
  el.timer = setTimeout(() => { el.hidden = true; }, seconds * 1000);
}
