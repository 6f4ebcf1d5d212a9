// The newest foot lock decisions of the open run, announced on the document whenever they change
// (loaded from the server, decided, or undone when the server refuses one), for the views that
// draw the locks (the contact timeline). decisions.js announces; others subscribe.

/** The name of the event; its `detail` is `{ runId, decisions }` (lock id -> "accept" | "reject"). */
export const LOCK_DECISIONS_EVENT = "mocapqa:lock-decisions";

/**
 * Announce the newest decision of each foot lock of run `runId`.
 *
 * @param runId   the run's id
 * @param latest  Map of lock id -> "accept" | "reject" (undecided locks are absent)
 * @param target  where the event is dispatched (the document; a parameter for tests)
 */
export function announceLockDecisions(runId, latest, target = globalThis.document) {
  if (!target) return;
  target.dispatchEvent(new CustomEvent(LOCK_DECISIONS_EVENT, { detail: { runId, decisions: Object.fromEntries(latest) } }));
}

/**
 * Call `handler(detail)` on each announcement until the returned function is called.
 *
 * @param handler called with `{ runId, decisions }`
 * @param target  where the events arrive (the document; a parameter for tests)
 * @returns the function that unsubscribes
 */
export function onLockDecisions(handler, target = globalThis.document) {
  if (!target) return () => {};
  const listener = (e) => handler(e.detail);
  target.addEventListener(LOCK_DECISIONS_EVENT, listener);
  return () => target.removeEventListener(LOCK_DECISIONS_EVENT, listener);
}
