// Plotly is loaded on demand, only by the views that draw charts: the take list never pays for
// its 1.5 MB. The server writes the script's address into <meta name="plotly-src">.
let loading = null;

export function loadPlotly() {
  if (window.Plotly) return Promise.resolve(window.Plotly);
  if (!loading) {
    loading = new Promise((resolve, reject) => {
      const script = document.createElement("script");
      script.src = document.querySelector('meta[name="plotly-src"]').content;
      script.addEventListener("load", () => resolve(window.Plotly));
      script.addEventListener("error", () => reject(new Error("could not load the charting library")));
      document.head.append(script);
    });
  }
  return loading;
}

/** Keep Plotly's (invisible until hovered) toolbar buttons out of the keyboard's tab order. */
export function untabbableModebar(div) {
  const fix = () => div.querySelectorAll(".modebar-btn, .modebar a").forEach((a) => a.setAttribute("tabindex", "-1"));
  fix();
  div.on("plotly_afterplot", fix);
}
