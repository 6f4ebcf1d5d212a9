"""The findings list, the contact timeline, the re-run form, compare and the shoot table as a
reviewer uses them, keyboard included, on 005_05 (a BVH take whose findings come in degrees and
in % of the body height): each worst value and the "at least" filter keep their unit, a sorted
column keeps the focus and travels in the link, the contact timeline's marks are reached with
the arrow keys, the re-run form offers no filter control a BVH take cannot use, compare does not
count the checks' order, and the shoot table's and the reviewed download's texts read right.
Screenshots go to ``tests/artifacts/`` (gitignored): ``fixes-findings-units.png``,
``fixes-contact-timeline.png``, ``fixes-rerun-filter.png``.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import httpx
import pytest
from tests.browser.test_workstation import ARTIFACTS, KNEES_TAKE, Page, run_again, wait_for_run

pytestmark = pytest.mark.browser

UNIT_LABELS = {"deg": "°"}


@pytest.fixture(scope="module")
def knees(live_server: str, corpus_dir: Path) -> dict[str, Any]:
    """005_05 uploaded into a shoot of its own, analysed with the default options."""
    api = f"{live_server}/api/v1"
    shoot = httpx.post(f"{api}/shoots", json={"name": "fixes"}, timeout=30).json()
    path = corpus_dir / KNEES_TAKE
    with path.open("rb") as stream:
        created = httpx.post(
            f"{api}/shoots/{shoot['id']}/takes",
            files=[("files", (path.name, stream))],
            timeout=120,
        )
    created.raise_for_status()
    take = created.json()["created"][0]
    wait_for_run(live_server, take["run_id"], path.name)
    result = httpx.get(f"{api}/runs/{take['run_id']}/result", timeout=30).json()
    return {"id": take["take_id"], "run": take["run_id"], "shoot": shoot["id"], "result": result}


@pytest.fixture
def page(chromium: Any) -> Iterator[Page]:
    opened = Page(chromium, width=1280, height=900)
    yield opened
    opened.close()


def shown_rows(page: Page) -> list[dict[str, Any]]:
    """The finding rows shown, in list order."""
    return page.page.locator("#findings tr.finding").evaluate_all(
        "rs => rs.map((r) => ({ kind: r.dataset.kind, joint: r.dataset.joint,"
        " start: Number(r.dataset.start), value: r.cells[4].innerText,"
        " confidence: r.cells[5].innerText }))"
    )


def test_worst_values_and_the_smallest_value_keep_their_unit(
    live_server: str, knees: dict[str, Any], page: Page
) -> None:
    p = page.page
    findings = knees["result"]["findings"]
    page.open_take(live_server, knees)
    # A joint with findings in degrees and in % height: one worst per unit, each with its unit.
    mixed = [
        j
        for j in {f["joint"] for f in findings}
        if len({f["unit"] for f in findings if f["joint"] == j and f["value"] is not None}) > 1
    ]
    assert mixed
    for joint in mixed:
        head = p.inner_text(f"#findings tr.group-head[data-joint='{joint}']")
        for unit in {f["unit"] for f in findings if f["joint"] == joint and f["value"] is not None}:
            worst = max(
                abs(f["value"])
                for f in findings
                if f["joint"] == joint and f["unit"] == unit and f["value"] is not None
            )
            assert f"{worst:.1f} {UNIT_LABELS.get(unit, unit)}" in head, head
    # "at least 2" in % height keeps the findings in % height of at least 2, and says so; the
    # findings in degrees are hidden, not compared with 2.
    p.locator("#filter-min").focus()
    p.keyboard.type("2")
    p.select_option("#filter-min-unit", "% height")
    p.wait_for_function(
        "() => document.getElementById('filter-min-note').textContent.includes('% height')"
    )
    expected = sorted(
        (f["start_frame"], f["joint"], f["kind"])
        for f in findings
        if f["unit"] == "% height" and f["value"] is not None and abs(f["value"]) >= 2
    )
    assert expected
    assert sorted((r["start"], r["joint"], r["kind"]) for r in shown_rows(page)) == expected
    assert all(r["value"].endswith("% height") for r in shown_rows(page))
    p.locator("#findings-panel").scroll_into_view_if_needed()
    p.screenshot(path=str(ARTIFACTS / "fixes-findings-units.png"))
    # The same number in degrees: the findings in degrees of at least 2°, no skate.
    p.select_option("#filter-min-unit", "deg")
    p.wait_for_function(
        "() => document.getElementById('filter-min-note').textContent.includes('°')"
    )
    in_degrees = sum(
        f["unit"] == "deg" and f["value"] is not None and abs(f["value"]) >= 2 for f in findings
    )
    assert len(shown_rows(page)) == in_degrees
    assert all(r["value"].endswith("°") for r in shown_rows(page))
    assert "unit=deg" in p.evaluate("() => location.hash")


def test_a_sorted_column_keeps_the_focus_and_the_link_keeps_the_order(
    live_server: str, knees: dict[str, Any], page: Page
) -> None:
    p = page.page
    page.open_take(live_server, knees)
    header = "#findings th.sortable[data-key='confidence']"
    p.locator(header).focus()
    p.keyboard.press("Enter")
    p.wait_for_function(
        "(s) => document.querySelector(s).getAttribute('aria-sort') === 'ascending'", arg=header
    )
    assert p.evaluate("() => document.activeElement.dataset.key") == "confidence"
    # Space sorts too (the other way), and does not scroll the page.
    scrolled = p.evaluate("() => window.scrollY")
    p.keyboard.press(" ")
    p.wait_for_function(
        "(s) => document.querySelector(s).getAttribute('aria-sort') === 'descending'", arg=header
    )
    assert p.evaluate("() => document.activeElement.dataset.key") == "confidence"
    assert p.evaluate("() => window.scrollY") == scrolled
    assert p.evaluate("() => window.mocapqaPlayer.playing") is False
    p.wait_for_function("() => /sort=confidence/.test(location.hash)")
    link = p.evaluate("() => location.hash")
    assert "order=desc" in link
    order = [(r["start"], r["joint"], r["kind"]) for r in shown_rows(page)]
    # Whoever opens the link sees the same order.
    p.goto("about:blank")
    p.goto(f"{live_server}/{link}")
    p.wait_for_selector("main[data-ready='1']", timeout=60_000)
    assert p.get_attribute(header, "aria-sort") == "descending"
    assert [(r["start"], r["joint"], r["kind"]) for r in shown_rows(page)] == order


def test_the_contact_timeline_is_walked_with_the_arrow_keys(
    live_server: str, knees: dict[str, Any], page: Page
) -> None:
    p = page.page
    page.open_take(live_server, knees, frame=0)
    timeline = p.locator("#contact-timeline")
    # One Tab stop: Tab from the control before it lands on it.
    assert timeline.locator("[tabindex='0']").count() == 1
    stops = timeline.locator("[role='button']")
    assert stops.count() == timeline.locator(".ct-bar, .ct-mark, .ct-lock").count()
    first = timeline.locator("[tabindex='0']")
    first.focus()
    label = p.evaluate("() => document.activeElement.getAttribute('aria-label')")
    assert label.startswith("left foot")
    # Right walks the left foot's row in time until a finding's mark (or a lock).
    for _ in range(20):
        p.keyboard.press("ArrowRight")
        kind = p.evaluate("() => document.activeElement.className")
        if kind != "ct-bar":
            break
    focused = p.evaluate(
        "() => ({ start: Number(document.activeElement.dataset.start),"
        " cls: document.activeElement.className,"
        " label: document.activeElement.getAttribute('aria-label') })"
    )
    assert focused["cls"] in ("ct-mark", "ct-lock"), focused
    assert focused["label"].startswith("left foot")
    # Enter goes to it, as a click does; the arrow keys did not step the frame.
    p.keyboard.press("Enter")
    p.wait_for_function(
        "(f) => document.getElementById('frame-label').innerText.startsWith(`frame ${f} `)",
        arg=focused["start"],
    )
    # Down reaches the right foot's row; Space goes there too.
    p.keyboard.press("ArrowDown")
    right = p.evaluate(
        "() => ({ start: Number(document.activeElement.dataset.start),"
        " label: document.activeElement.getAttribute('aria-label') })"
    )
    assert right["label"].startswith("right foot")
    p.keyboard.press(" ")
    p.wait_for_function(
        "(f) => document.getElementById('frame-label').innerText.startsWith(`frame ${f} `)",
        arg=right["start"],
    )
    assert timeline.locator("[tabindex='0']").count() == 1
    timeline.scroll_into_view_if_needed()
    p.screenshot(path=str(ARTIFACTS / "fixes-contact-timeline.png"))


def test_the_rerun_form_offers_no_filter_control_a_bvh_take_cannot_use(
    live_server: str, knees: dict[str, Any], page: Page
) -> None:
    p = page.page
    page.open_take(live_server, knees)
    assert knees["result"]["steps"]["filter"]["state"] == "skipped"
    panel = p.locator("#rerun-panel")
    panel.scroll_into_view_if_needed()
    box = panel.locator("input[name=check][value='filter']")
    # No filter chosen, none by default: the box says nothing runs, no empty preset menu.
    assert box.is_disabled()
    assert not box.is_checked()
    assert not p.locator("#filter-preset").is_visible()
    assert "No filter chosen" in p.inner_text("#filter-none")
    p.screenshot(path=str(ARTIFACTS / "fixes-rerun-filter.png"))
    # Choosing a filter from the keyboard makes the check available, with its presets.
    p.locator("#filter-method").focus()
    p.keyboard.press("ArrowDown")
    p.wait_for_function(
        "() => !document.querySelector(\"input[name=check][value='filter']\").disabled"
    )
    assert p.locator("#filter-preset").is_visible()
    assert p.locator("#filter-preset option").count() >= 1
    assert not p.locator("#filter-none").is_visible()
    box.focus()
    p.keyboard.press(" ")
    assert box.is_checked()


def test_compare_ignores_the_order_of_the_checks(
    live_server: str, knees: dict[str, Any], page: Page
) -> None:
    p = page.page
    first = knees["result"]["options"]["checks"]
    reordered = run_again(live_server, knees["id"], {"checks": list(reversed(first))})
    p.goto(f"{live_server}/#/compare?a={knees['run']}&b={reordered}")
    p.wait_for_selector("main[data-ready='1']", timeout=60_000)
    assert p.inner_text("#compare-options") == "Same options."
    # Nor is a check that cannot run on a motion take (markers) a difference.
    asked = sorted({*first, "markers"})
    without = run_again(live_server, knees["id"], {"checks": [c for c in asked if c != "markers"]})
    with_markers = run_again(live_server, knees["id"], {"checks": asked})
    p.goto(f"{live_server}/#/compare?a={with_markers}&b={without}")
    p.wait_for_selector("main[data-ready='1']", timeout=60_000)
    assert p.inner_text("#compare-options") == "Same options."


def test_the_shoot_table_and_the_reviewed_download_say_their_units_and_counts(
    live_server: str, knees: dict[str, Any], page: Page
) -> None:
    p = page.page
    locks = [
        f for f in knees["result"]["findings"] if f["kind"] == "skate" and isinstance(f["id"], str)
    ]
    assert locks
    page.open_take(live_server, knees)
    p.wait_for_function(
        "() => / applied\\)$/.test(document.getElementById('download-decided').textContent)"
    )
    n = len(locks)
    expected = f"Download reviewed take (0 of {n} foot lock{'' if n == 1 else 's'} applied)"
    assert p.inner_text("#download-decided") == expected
    # The shoot table: the worst skate's header names no unit its BVH cell does not show.
    p.goto(f"{live_server}/#/shoot/{knees['shoot']}")
    p.wait_for_selector("#shoot-takes tbody tr", timeout=60_000)
    header = p.inner_text("#shoot-takes th[data-sort='foot_worst_skate']")
    assert "cm" not in header
    keys = p.locator("#shoot-takes th[data-sort]").evaluate_all(
        "ths => ths.map((th) => th.dataset.sort)"
    )
    texts = p.locator("#shoot-takes tbody tr").first.locator("td").all_inner_texts()[1:]
    cell = dict(zip(keys, texts, strict=True))["foot_worst_skate"]
    assert re.fullmatch(r"\d+\.\d % height", cell), cell
