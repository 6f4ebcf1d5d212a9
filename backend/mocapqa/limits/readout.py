"""Anatomical read-out of a limit violation: "right knee hyperextended 14°".

Canonical frames (:mod:`mocapqa.limits.canonical`) have ``x`` toward the body's left (forward
for a clavicle), ``y`` along the segment and ``z = x × y``; the limits parameters are taken
relative to the model's mean pose of the role. So ``s1`` is a rotation about the flexion
axis, ``s2`` about the third axis (abduction/adduction) and ``τ`` about the segment
(axial rotation). With the limbs hanging (the corpus' mean pose), a positive ``s1`` moves the
distal end backward, a positive ``s2`` toward the body's right and a positive ``τ`` turns the
front of a segment toward the body's right. The terms below follow from that, per role and
side; they assume the mean pose is near the anatomical one (arms down, legs straight), which
holds for the shipped canonical model. A hand's terms assume the palm faces forward.
"""

from __future__ import annotations

from collections.abc import Sequence

__all__ = ["anatomical_terms", "violation_text"]

# role → (place for s1, s2, τ; (negative, positive) terms of s1, s2 and τ) for the LEFT side.
_LEFT: dict[str, tuple[tuple[str, str, str], tuple[tuple[str, str], ...]]] = {
    "clavicle": (("clavicle", "clavicle", "clavicle"),
                 (("depressed", "elevated"), ("protracted", "retracted"),
                  ("rotated backward", "rotated forward"))),
    "upper_arm": (("shoulder", "shoulder", "shoulder"),
                  (("over-flexed", "over-extended"), ("over-abducted", "over-adducted"),
                   ("over-rotated externally", "over-rotated internally"))),
    "forearm": (("elbow", "elbow", "forearm"),
                (("over-flexed", "hyperextended"), ("bent outward", "bent inward"),
                 ("over-supinated", "over-pronated"))),
    "hand": (("wrist", "wrist", "hand"),
             (("over-flexed", "over-extended"), ("over-deviated radially", "over-deviated ulnarly"),
              ("twisted outward", "twisted inward"))),
    "upper_leg": (("hip", "hip", "hip"),
                  (("over-flexed", "over-extended"), ("over-abducted", "over-adducted"),
                   ("over-rotated externally", "over-rotated internally"))),
    "lower_leg": (("knee", "knee", "knee"),
                  (("hyperextended", "over-flexed"), ("bent outward", "bent inward"),
                   ("over-rotated externally", "over-rotated internally"))),
    "foot": (("ankle", "ankle", "ankle"),
             (("over-dorsiflexed", "over-plantarflexed"), ("over-abducted", "over-adducted"),
              ("over-inverted", "over-everted"))),
}  # fmt: skip
# On the right side a mirrored motion flips s2 and τ (and a clavicle's s1: its z points down).
_MIRRORED = {"clavicle": (True, False, True)}


def anatomical_terms(role_key: str) -> tuple[tuple[str, str, str], tuple[tuple[str, str], ...]]:
    """Places and (negative, positive) terms of ``s1``, ``s2``, ``τ`` for a role key.

    Parameters
    ----------
    role_key : str
        E.g. ``"right_lower_leg"``.
    """
    side, _, role = role_key.partition("_")
    places, terms = _LEFT[role]
    if side == "left":
        return places, terms
    flips = _MIRRORED.get(role, (False, True, True))
    mirrored = tuple((t[1], t[0]) if flip else t for t, flip in zip(terms, flips, strict=True))
    return places, mirrored


def violation_text(role_key: str, excess_deg: Sequence[float], min_deg: float = 1.0) -> str:
    """One line naming the anatomical directions a frame leaves the limits in.

    Parameters
    ----------
    role_key : str
        E.g. ``"right_lower_leg"``.
    excess_deg : sequence of 3 float
        Signed excess of ``(s1, s2, τ)`` beyond the limits
        (:func:`mocapqa.limits.occupancy.signed_excess`), degrees.
    min_deg : float
        Components smaller than this are left out.

    Returns
    -------
    str
        E.g. ``"right knee hyperextended 14°, rotated internally 3°"``; ``""`` for a role
        without anatomical terms.

    Examples
    --------
    >>> violation_text("right_lower_leg", [-14.2, 0.0, 0.0])
    'right knee hyperextended 14°'
    """
    side, _, role = role_key.partition("_")
    if role not in _LEFT:
        return ""
    places, terms = anatomical_terms(role_key)
    parts = sorted(
        ((abs(float(v)), k) for k, v in enumerate(excess_deg) if abs(float(v)) >= min_deg),
        reverse=True,
    )
    if not parts:
        return f"{side} {places[0]} at the edge of its limits (<{min_deg:g}°)"
    phrases = []
    for magnitude, k in parts:
        term = terms[k][1 if excess_deg[k] > 0 else 0]
        place = places[k]
        phrases.append(f"{side} {place} {term} {magnitude:.0f}°")
    return ", ".join(phrases)
