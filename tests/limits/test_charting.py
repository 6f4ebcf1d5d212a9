"""The check's hot path: component-major canonical rotations against the plain composition."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from mocapqa.io.bvh import read_bvh
from mocapqa.kinematics.forward import forward_kinematics
from mocapqa.kinematics.quaternion import conjugate, multiply
from mocapqa.limits.canonical import CANONICAL_AXIS, canonical_frames
from mocapqa.limits.charting import canonical_params, canonical_rotations, product
from mocapqa.limits.expmap import expmap_from_quats


def test_the_component_major_product_is_the_hamilton_product() -> None:
    rng = np.random.default_rng(0)
    p, q = rng.normal(size=(2, 50, 3, 4))
    np.testing.assert_allclose(
        np.moveaxis(product(np.moveaxis(p, -1, 0), np.moveaxis(q, -1, 0)), 0, -1),
        multiply(p, q),
        atol=1e-15,
    )


def test_canonical_rotations_compose_world_rotations_and_frames(corpus_dir: Path) -> None:
    # A Character Creator take: a deep hierarchy (spine chain, twist bones) under the roles.
    motion = read_bvh(corpus_dir / "bvh" / "cmu" / "iclone" / "002_03.bvh")
    frames = canonical_frames(motion)
    world, _ = forward_kinematics(motion)
    expected = multiply(
        conjugate(multiply(world[:, frames.parents], frames.parent_frames[None])),
        multiply(world[:, frames.joints], frames.frames[None]),
    )
    got = canonical_rotations(motion, frames)
    assert got.shape == (motion.n_frames, len(frames.roles), 4)
    # q and −q are one rotation: compare up to sign.
    sign = np.sign(np.sum(got * expected, axis=-1, keepdims=True))
    np.testing.assert_allclose(got, sign * expected, atol=1e-9)
    np.testing.assert_allclose(
        canonical_params(motion, frames, CANONICAL_AXIS),
        expmap_from_quats(got, CANONICAL_AXIS),
        atol=1e-12,
    )
