"""The paper's synthetic labelling and the per-joint network."""

from __future__ import annotations

import numpy as np
import pytest

from mocapqa.errors import InputError
from mocapqa.limits.discriminator import (
    DiscriminatorParams,
    network_valid,
    synthetic_labels,
    train_discriminator,
)
from mocapqa.limits.occupancy import OccupancyMap, OccupancyParams, build_occupancy


def _blob_map() -> OccupancyMap:
    rng = np.random.default_rng(0)
    swing = rng.normal(0.0, 0.4, (3000, 2))
    tau = 0.5 * swing[:, 0] + rng.uniform(-0.3, 0.3, 3000)
    return build_occupancy(np.column_stack((swing, tau)), OccupancyParams(bin_deg=10.0))


def test_synthetic_sets_are_balanced_and_labelled_by_the_map() -> None:
    from mocapqa.limits.occupancy import is_valid

    occupancy = _blob_map()
    params, labels = synthetic_labels(occupancy, 500, np.random.default_rng(1))
    assert params.shape == (1000, 3)
    assert labels.sum() == 500
    np.testing.assert_array_equal(is_valid(occupancy, params), labels)
    assert np.all(np.abs(params) <= np.pi)


def test_a_small_network_learns_a_compact_region() -> None:
    occupancy = _blob_map()
    settings = DiscriminatorParams(n_valid=1500, hidden_sizes=(16,), max_iter=300)
    network, scores = train_discriminator(occupancy, settings, np.random.default_rng(2))
    assert scores.accuracy > 0.9
    assert scores.hidden_size == 16
    inside = np.array([[0.0, 0.0, 0.0]])
    far = np.array([[2.5, -2.5, 3.0]])
    assert network_valid(network, inside)[0]
    assert not network_valid(network, far)[0]


def test_bad_training_settings_are_refused() -> None:
    with pytest.raises(InputError, match=r"Expected hidden sizes in 1\.\.256"):
        DiscriminatorParams(hidden_sizes=(0,))
    with pytest.raises(InputError, match="Expected `activation`"):
        DiscriminatorParams(activation="sigmoid")
    with pytest.raises(InputError, match="Expected `solver`"):
        DiscriminatorParams(solver="sgd")


def test_both_solvers_store_a_network_that_reproduces_its_scores() -> None:
    from mocapqa.limits.occupancy import is_valid

    occupancy = _blob_map()
    for solver in ("lbfgs", "adam"):
        settings = DiscriminatorParams(n_valid=1000, hidden_sizes=(8,), max_iter=200, solver=solver)
        network, scores = train_discriminator(occupancy, settings, np.random.default_rng(3))
        # The stored network takes raw radians: the input standardisation is folded into it.
        fresh, labels = synthetic_labels(occupancy, 1000, np.random.default_rng(4))
        assert np.mean(network_valid(network, fresh) == labels) > 0.85
        assert np.array_equal(labels, is_valid(occupancy, fresh))
        assert 0.85 < scores.accuracy <= 1.0


def test_the_ensemble_size_leaves_the_build_stream_alone() -> None:
    occupancy = _blob_map()
    alone = DiscriminatorParams(n_valid=400, hidden_sizes=(8,), max_iter=100)
    ensemble = DiscriminatorParams(n_valid=400, hidden_sizes=(8, 4), seeds_per_size=2, max_iter=100)
    after = []
    for settings in (alone, ensemble):
        rng = np.random.default_rng(5)
        train_discriminator(occupancy, settings, rng)
        after.append(rng.integers(2**31 - 1, size=4))
    # The next joint's synthetic set is drawn from the same stream position either way.
    np.testing.assert_array_equal(after[0], after[1])
