"""The anatomical read-out of limit violations."""

from __future__ import annotations

from mocapqa.limits.readout import violation_text


def test_each_side_reads_mirrored_terms() -> None:
    assert violation_text("right_lower_leg", [-14.2, 0.0, 0.0]) == "right knee hyperextended 14°"
    assert violation_text("left_lower_leg", [30.0, 0.0, 0.0]) == "left knee over-flexed 30°"
    # A positive twist turns the front toward the body's right: inward on the left forearm,
    # outward on the right one.
    assert violation_text("left_forearm", [0.0, 0.0, 35.0]) == "left forearm over-pronated 35°"
    assert violation_text("right_forearm", [0.0, 0.0, 35.0]) == "right forearm over-supinated 35°"
    assert violation_text("right_upper_leg", [0.0, 12.0, 0.0]) == "right hip over-abducted 12°"
    assert violation_text("left_upper_leg", [0.0, 12.0, 0.0]) == "left hip over-adducted 12°"


def test_components_are_listed_largest_first_and_tiny_ones_dropped() -> None:
    text = violation_text("left_upper_arm", [-5.0, 0.4, -20.0])
    assert text == "left shoulder over-rotated externally 20°, left shoulder over-flexed 5°"
    assert (
        violation_text("left_foot", [0.2, 0.0, 0.0]) == "left ankle at the edge of its limits (<1°)"
    )
    assert violation_text("left_spine", [10.0, 0.0, 0.0]) == ""
