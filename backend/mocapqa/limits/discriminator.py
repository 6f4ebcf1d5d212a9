"""Per-joint discriminator: a one-hidden-layer network trained on the map's synthetic labels.

Conventions
-----------
The paper's protocol (methods §2): sample ``(s1, s2, τ)`` uniformly in ``[−π, π]³``, label each
sample with the lookup map's ``isValid``, keep a balanced 50/50 set and split it 70/15/15 into
training, validation and test sets. Valid samples are drawn uniformly over the valid region
directly (a bin chosen in proportion to its twist interval, then a uniform point in the bin and
the interval, wrapped to ±180°; with interpolated bounds the interval is widened and the points
the map rejects are dropped), which has the distribution of rejection sampling from the cube
without its cost on sparse maps. A small ensemble, one network per hidden size (4–32 units;
default 32 and 16) and seed, is trained with scikit-learn; the one with the best validation
accuracy is kept and scored once on the test set. The first network's seed is drawn from the
build's random stream and the other members' from a child stream, so the ensemble's size does
not change the synthetic sets of the joints that follow.

Training inputs are standardised: centred on the mean of the valid training samples and divided
by twice their standard deviation, so the valid region spans about ``[−1, 1]`` on each axis
whatever its size. The default solver is full-batch L-BFGS, which on these small sets reaches a
tighter boundary than Adam in fewer passes; BLAS runs on one thread while training (several
threads only contend on matrices this small).

A trained network is stored as plain arrays (:class:`Network`) and evaluated with numpy, so a
model file never holds pickled objects. Stored inputs are the parameters divided by π: the
standardisation is folded into the hidden layer's weights and biases.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from mocapqa.core.arrays import BoolArray, FloatArray, as_float_array
from mocapqa.errors import InputError
from mocapqa.limits.occupancy import OccupancyMap, is_valid

__all__ = [
    "DiscriminatorParams",
    "DiscriminatorScores",
    "Network",
    "network_valid",
    "synthetic_labels",
    "train_discriminator",
]

_ACTIVATIONS = ("relu", "tanh")
_SOLVERS = ("lbfgs", "adam")


@dataclass(frozen=True, slots=True)
class DiscriminatorParams:
    """Training parameters.

    Parameters
    ----------
    n_valid : int
        Valid samples in the balanced synthetic set (as many invalid ones are drawn). The
        paper fixes no count; 20,000 (6,000 test samples) lets a 32-unit network reach 97 %
        on the large Character Creator maps, where 5,000 left a 1–1.5 % train–test gap.
    hidden_sizes : tuple of int
        Hidden-layer sizes tried (paper: 4, 8, 16, 32); the best by validation is kept. The
        first size's first network takes the build stream's seed (see the module notes).
    seeds_per_size : int
        Networks trained per hidden size; ensemble size = sizes × seeds (paper: 20 in all).
    max_iter : int
        Iterations per network: L-BFGS iterations, or Adam epochs (learning rate 0.01).
    activation : {"relu", "tanh"}
    solver : {"lbfgs", "adam"}
    """

    n_valid: int = 20000
    hidden_sizes: tuple[int, ...] = (32, 16)
    seeds_per_size: int = 1
    max_iter: int = 1500
    activation: str = "tanh"
    solver: str = "lbfgs"

    def __post_init__(self) -> None:
        if self.n_valid < 20 or self.seeds_per_size < 1 or self.max_iter < 1:
            raise InputError(
                "Expected `n_valid` >= 20, `seeds_per_size` >= 1 and `max_iter` >= 1, got "
                f"{self.n_valid}, {self.seeds_per_size} and {self.max_iter}"
            )
        if not self.hidden_sizes or any(not 1 <= h <= 256 for h in self.hidden_sizes):
            raise InputError(f"Expected hidden sizes in 1..256, got {self.hidden_sizes}")
        if self.activation not in _ACTIVATIONS:
            raise InputError(f"Expected `activation` in {_ACTIVATIONS}, got {self.activation!r}")
        if self.solver not in _SOLVERS:
            raise InputError(f"Expected `solver` in {_SOLVERS}, got {self.solver!r}")


@dataclass(frozen=True, slots=True)
class Network:
    """A one-hidden-layer classifier as arrays: ``σ(act(x W1 + b1) W2 + b2) ≥ 0.5`` is valid.

    Parameters
    ----------
    hidden_weights : ndarray, shape (3, H)
    hidden_biases : ndarray, shape (H,)
    output_weights : ndarray, shape (H,)
    output_bias : float
    activation : {"relu", "tanh"}
    """

    hidden_weights: FloatArray
    hidden_biases: FloatArray
    output_weights: FloatArray
    output_bias: float
    activation: str = "relu"

    def __post_init__(self) -> None:
        w1 = as_float_array(self.hidden_weights, "hidden_weights", (3, "H"))
        h = w1.shape[1]
        object.__setattr__(self, "hidden_weights", w1)
        object.__setattr__(
            self, "hidden_biases", as_float_array(self.hidden_biases, "hidden_biases", (h,))
        )
        object.__setattr__(
            self, "output_weights", as_float_array(self.output_weights, "output_weights", (h,))
        )
        object.__setattr__(self, "output_bias", float(self.output_bias))
        if self.activation not in _ACTIVATIONS:
            raise InputError(f"Expected `activation` in {_ACTIVATIONS}, got {self.activation!r}")


@dataclass(frozen=True, slots=True)
class DiscriminatorScores:
    """Held-out test-split scores of the kept network.

    Parameters
    ----------
    accuracy, precision, recall : float
        On the test split; "positive" means valid.
    hidden_size : int
        Hidden size of the kept network.
    n_test : int
        Test samples.
    """

    accuracy: float
    precision: float
    recall: float
    hidden_size: int
    n_test: int


def network_valid(network: Network, params: FloatArray) -> BoolArray:
    """Whether the network calls ``params (..., 3)`` (radians) valid, shape ``(...)``."""
    hidden = (params / np.pi) @ network.hidden_weights + network.hidden_biases
    hidden = np.maximum(hidden, 0.0) if network.activation == "relu" else np.tanh(hidden)
    return np.asarray(hidden @ network.output_weights + network.output_bias >= 0.0)


def synthetic_labels(
    occupancy: OccupancyMap, n_valid: int, rng: np.random.Generator
) -> tuple[FloatArray, BoolArray]:
    """A balanced, shuffled synthetic set labelled by the lookup map.

    Parameters
    ----------
    occupancy : OccupancyMap
    n_valid : int
        Number of valid samples; the same number of invalid ones is drawn.
    rng : numpy.random.Generator

    Returns
    -------
    params : ndarray, shape (2 n_valid, 3)
        ``(s1, s2, τ)`` in radians.
    labels : ndarray of bool, shape (2 n_valid,)
    """
    width = np.deg2rad(occupancy.bin_deg)
    i1, i2 = np.nonzero(occupancy.occupied)
    # Drawn from each bin's own arc, widened by a quarter turn when the bounds are
    # interpolated (they vary inside a bin), then kept only where the map says valid.
    extra = 0.25 * np.pi if occupancy.interpolate else 0.0
    lows = occupancy.tau_min[i1, i2] - extra
    spans = np.minimum(occupancy.tau_max[i1, i2] + extra - lows, 2.0 * np.pi)
    weights = np.maximum(spans, 1e-9)
    valid = np.empty((0, 3))
    while valid.shape[0] < n_valid:
        pick = rng.choice(i1.size, size=n_valid, p=weights / weights.sum())
        draw = np.column_stack(
            (
                -np.pi + (i1[pick] + rng.random(n_valid)) * width,
                -np.pi + (i2[pick] + rng.random(n_valid)) * width,
                (lows[pick] + rng.random(n_valid) * spans[pick] + np.pi) % (2.0 * np.pi) - np.pi,
            )
        )
        valid = np.concatenate((valid, draw[is_valid(occupancy, draw)]))
    valid = valid[:n_valid]
    invalid = np.empty((0, 3))
    while invalid.shape[0] < n_valid:
        draw = rng.uniform(-np.pi, np.pi, size=(4 * n_valid, 3))
        invalid = np.concatenate((invalid, draw[~is_valid(occupancy, draw)]))
    params = np.concatenate((valid, invalid[:n_valid]))
    labels = np.concatenate((np.ones(n_valid, bool), np.zeros(n_valid, bool)))
    order = rng.permutation(params.shape[0])
    return params[order], labels[order]


def _scores(predicted: BoolArray, labels: BoolArray) -> tuple[float, float, float]:
    tp = float(np.sum(predicted & labels))
    accuracy = float(np.mean(predicted == labels))
    precision = tp / max(float(np.sum(predicted)), 1.0)
    recall = tp / max(float(np.sum(labels)), 1.0)
    return accuracy, precision, recall


def train_discriminator(
    occupancy: OccupancyMap, settings: DiscriminatorParams, rng: np.random.Generator
) -> tuple[Network, DiscriminatorScores]:
    """Train the per-joint ensemble on synthetic labels and keep the best by validation.

    Parameters
    ----------
    occupancy : OccupancyMap
        The joint's lookup map, the labeller.
    settings : DiscriminatorParams
    rng : numpy.random.Generator
        Source of the synthetic samples and of the networks' seeds.

    Returns
    -------
    network : Network
    scores : DiscriminatorScores
        Accuracy, precision and recall on the held-out 15 % test split.
    """
    from sklearn.exceptions import ConvergenceWarning
    from sklearn.neural_network import MLPClassifier
    from threadpoolctl import threadpool_limits  # type: ignore[import-untyped]

    params, labels = synthetic_labels(occupancy, settings.n_valid, rng)
    n = params.shape[0]
    n_train, n_val = int(0.70 * n), int(0.15 * n)
    train, val, test = slice(0, n_train), slice(n_train, n_train + n_val), slice(n_train + n_val, n)
    inside = params[train][labels[train]]
    centre = inside.mean(axis=0)
    spread = np.maximum(2.0 * inside.std(axis=0), 1e-3)
    x = (params - centre) / spread
    best: tuple[float, Network, int] | None = None
    # The first network's seed comes from the build's stream; the other members' seeds from
    # a child stream, which draws nothing from it, so the ensemble's size never changes the
    # synthetic sets of the joints built after this one.
    members = rng.spawn(1)[0]
    sizes = [size for size in settings.hidden_sizes for _ in range(settings.seeds_per_size)]
    for index, size in enumerate(sizes):
        seed = int((rng if index == 0 else members).integers(2**31 - 1))
        if settings.solver == "lbfgs":
            classifier = MLPClassifier(
                hidden_layer_sizes=(size,),
                activation=settings.activation,
                solver="lbfgs",
                max_iter=settings.max_iter,
                max_fun=10 * settings.max_iter,
                tol=0.0,
                random_state=seed,
            )
        else:
            classifier = MLPClassifier(
                hidden_layer_sizes=(size,),
                activation=settings.activation,
                max_iter=settings.max_iter,
                learning_rate_init=0.01,
                random_state=seed,
            )
        with warnings.catch_warnings(), threadpool_limits(limits=1, user_api="blas"):
            warnings.simplefilter("ignore", ConvergenceWarning)
            classifier.fit(x[train], labels[train])
        weights = classifier.coefs_[0]
        network = Network(
            hidden_weights=weights * (np.pi / spread)[:, None],
            hidden_biases=classifier.intercepts_[0] - (centre / spread) @ weights,
            output_weights=classifier.coefs_[1][:, 0],
            output_bias=float(classifier.intercepts_[1][0]),
            activation=settings.activation,
        )
        accuracy = float(np.mean(network_valid(network, params[val]) == labels[val]))
        if best is None or accuracy > best[0]:
            best = (accuracy, network, size)
    if best is None:  # unreachable: hidden_sizes is non-empty
        raise InputError("Expected at least one hidden size, got none")
    _, network, size = best
    accuracy, precision, recall = _scores(network_valid(network, params[test]), labels[test])
    return network, DiscriminatorScores(accuracy, precision, recall, size, n - n_train - n_val)
