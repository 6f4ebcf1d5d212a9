// The shoot view's joint-limits model: which model the runs of the shoot's takes use. Everyone
// who may read the shoot sees it; an admin (action "choose_limits_model") chooses it from the
// models the server offers (GET /limits-models: the default, the shipped and the registered).
// Takes whose latest run used another model are counted, and an admin can run them again.
import * as api from "./api.js";
import { h } from "./dom.js";

/** One line per model for the picker: its name and what it covers. */
export function modelLabel(model) {
  if (model.kind === "default") return "default (the shipped choice for each rig)";
  const covers = model.frame === "canonical" ? "any rig with limb roles" : `${model.rig_family} rig only`;
  const origin = model.kind === "registered" ? "registered" : "shipped";
  return `${model.name} (${origin}; ${covers}; ${model.n_takes} take${model.n_takes === 1 ? "" : "s"})`;
}

/** What the shoot's `limits_stale_takes` means, "" when every latest run used its model. */
export function staleNote(shoot) {
  const n = shoot.limits_stale_takes || 0;
  if (n === 0) return "";
  const takes = n === 1 ? "1 take's latest run" : `${n} takes' latest runs`;
  return `${takes} checked joint limits with another model than ${shoot.limits_model}`;
}

/** What a re-run request did (POST /shoots/{id}/limits-reruns). */
export function rerunNote(answer) {
  const n = answer.queued.length;
  const queued = `${n} run${n === 1 ? "" : "s"} queued with ${answer.limits_model}`;
  return answer.remaining ? `${queued}; ${answer.remaining} left (your queue is full: press again later)` : queued;
}

/** Whether `me` (GET /me) may choose a shoot's limits model. */
export const mayChooseModel = (me) => new Set((me && me.can) || []).has("choose_limits_model");

// The picker saves the choice it settles on: arrow keys move through the models one change
// event at a time, so a save waits this long after the last one (and the list keeps the focus).
const SAVE_DELAY_MS = 500;

/** The panel: the model's name, and for an admin a picker that saves the settled choice and a
 * button that runs the stale takes again (`onQueued()` after runs were queued). */
export async function limitsModelPanel(shoot, me, onQueued = () => {}) {
  const panel = h("div", { class: "controls", id: "limits-model-panel" });
  const label = h("span", {}, "joint-limits model ");
  const stale = h("span", { id: "limits-model-stale", class: "muted" }, staleNote(shoot));
  if (!mayChooseModel(me)) {
    panel.append(label, h("strong", { id: "limits-model-name" }, shoot.limits_model), stale);
    return panel;
  }
  const rerun = h("button", { type: "button", id: "limits-rerun", hidden: !shoot.limits_stale_takes },
    "run them again");
  const showStale = () => {
    stale.textContent = staleNote(shoot);
    rerun.hidden = !shoot.limits_stale_takes;
  };
  const models = await api.limitsModels();
  const message = h("span", { id: "limits-model-message", class: "muted", role: "status" });
  const select = h("select", { id: "limits-model", "aria-label": "joint-limits model of this shoot" },
    models.map((m) => h("option", { value: m.name, selected: m.name === shoot.limits_model }, modelLabel(m))));
  let pending = null;
  const save = async () => {
    const chosen = select.value;
    if (chosen === shoot.limits_model) { message.className = "muted"; message.textContent = ""; return; }
    try {
      const saved = await api.setShootLimitsModel(shoot.id, chosen);
      shoot.limits_model = saved.limits_model;
      shoot.limits_stale_takes = saved.limits_stale_takes;
      showStale();
      message.className = "muted";
      message.textContent = `saved: runs started from now on use ${saved.limits_model}`;
    } catch (error) {
      select.value = shoot.limits_model;
      message.className = "error";
      message.textContent = error.message;
    }
  };
  select.addEventListener("change", () => {
    clearTimeout(pending);
    message.className = "muted";
    message.textContent = "saving…";
    pending = setTimeout(save, SAVE_DELAY_MS);
  });
  rerun.addEventListener("click", async () => {
    rerun.disabled = true;
    try {
      const answer = await api.rerunStaleLimits(shoot.id);
      shoot.limits_stale_takes = answer.remaining;
      showStale();
      message.className = "muted";
      message.textContent = rerunNote(answer);
      if (answer.queued.length) onQueued();
    } catch (error) {
      message.className = "error";
      message.textContent = error.message;
    } finally { rerun.disabled = false; }
  });
  panel.append(h("label", {}, label, select), stale, rerun, message);
  return panel;
}
