"""The one training loop every chapter uses: seeded, with a progress bar, early stopping and a
checkpoint in ``data/cache/``.

Conventions
-----------
Data
    A training set is a list of programs; program ``i`` has inputs ``xs[i]`` of shape
    (N_i, n_inputs) and targets ``ys[i]`` of shape (N_i, n_outputs), one row per G-line. NaN
    targets are left out of the loss (a G-line whose target is undefined).
Split
    Whole programs are held out for validation (a share ``val_share``, at least one), so that
    validation G-lines never share a program with training G-lines.
Scaling
    Inputs (optionally the logarithm of some columns) and targets are standardised with the mean
    and standard deviation of the *training* programs only; the validation programs and every
    later input are scaled with those statistics (:class:`Scaler`).
Windows
    Sequence models train on windows of ``window_lines`` consecutive G-lines, cut at a random
    offset each epoch, so that one batch runs many programs in parallel. Prediction runs
    overlapping windows of the same length and keeps the middle half of each (a quarter of the
    window of context on either side), which is also what makes it fast (:meth:`Trained.predict`).
Determinism
    The initial weights, the window offsets and the batch order are drawn from generators seeded
    with ``seed``, and so are dropout masks (torch's global generator, seeded with ``seed``
    inside :func:`torch.random.fork_rng`, so the caller's random state is untouched);
    :func:`fit` runs with
    ``torch.use_deterministic_algorithms(True)``, one torch intra-op thread
    (``torch.set_num_threads(1)``) and one BLAS thread (:func:`threadpoolctl.threadpool_limits`):
    summation order, hence rounding, depends on the thread count. It restores all three when it
    returns. The same data and configs give the same weights, bit for bit, on one machine.
Steps
    A step is autograd and a :mod:`torch.optim` optimiser, for every network. SGD runs
    :func:`torch.optim.sgd.sgd`, the update :class:`torch.optim.SGD` runs, called directly
    (:class:`_SGD`): the optimiser object's bookkeeping of a step (profiler scopes, hooks,
    parameter groups) cost a fifth of a BP network's step. The BP network's batches of windows
    run as one (rows, n_inputs) matrix, masked by a float32 mask: the same products, without
    the autograd nodes that reshape (windows, rows, n) inputs or the casts of a bool mask.
    Both give the same bits. BP networks that differ in seed or dropout only can also train
    as one stack, each as it would alone (:func:`nctwin.learn.stack.fit_stack`).
Checkpoints
    ``data/cache/models/<name>-<hash>.pt``, keyed by a SHA-256 of the data, the model config,
    the training config, the CPU kernels torch runs and ``make``'s kernel pins (:data:`KERNEL_PINS`;
    unpinned MKL rounds differently even on an AVX2-only CPU), so that a network trained outside
    ``make`` is never reused by a chapter run through it. Written atomically (temporary file, then
    ``os.replace``) and read with ``torch.load(..., weights_only=True)``: the file holds
    tensors and plain Python values only, never pickled objects. A training that diverges
    (:class:`TrainingDivergedError`) leaves ``<name>-<hash>.diverged``, its message, so that
    asking again raises again without training; it stops at the first NaN weight, after which
    no validation loss can be finite.
"""

from __future__ import annotations

import copy
import math
import os
import time
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np
import torch
from threadpoolctl import threadpool_limits
from torch.optim.sgd import sgd
from tqdm import tqdm

from ..cache import atomic_write, atomic_write_text, cache_path, content_key
from .models import BPConfig, BPNetwork, ModelConfig, SequenceModel, build, build_bp

__all__ = [
    "KERNEL_PINS",
    "Scaler",
    "TrainConfig",
    "Trained",
    "TrainingDivergedError",
    "checkpoint_path",
    "data_hash",
    "deterministic",
    "fit",
    "load_checkpoint",
    "one_thread",
    "scaled_programs",
]


#: Environment variables with which ``make`` pins the CPU kernels (Makefile), in every key.
KERNEL_PINS = ("ATEN_CPU_CAPABILITY", "MKL_CBWR", "ONEDNN_MAX_CPU_ISA", "OPENBLAS_CORETYPE",
               "NPY_DISABLE_CPU_FEATURES")  # fmt: skip


class TrainingDivergedError(RuntimeError):
    """Raised by :func:`fit` when no epoch had a finite validation loss."""


@dataclass(frozen=True)
class TrainConfig:
    """How to train.

    Parameters
    ----------
    seed : int
    max_epochs : int
    patience : int
        Stop after this many epochs without a lower validation loss; the best weights are kept.
    batch_size : int
        Windows per optimiser step.
    window_lines : int
        G-lines per training window (and per prediction window).
    learning_rate : float
        Step size of the optimiser.
    val_share : float
        Share of programs held out for validation.
    loss : {"rmse", "mse"}
        Root mean square error (Chien et al. 2023, Sec. 3) or mean square error, of the scaled
        targets.
    log_inputs : tuple of int
        Input columns standardised as logarithms (lengths spanning decades).
    optimiser : {"adam", "sgd"}
        Adam, or stochastic gradient descent with ``momentum`` (Zhang et al. 2023, eq. 14).
    momentum : float
        Momentum :math:`\beta` of ``"sgd"``, in [0, 1).
    """

    seed: int = 0
    max_epochs: int = 200
    patience: int = 20
    batch_size: int = 32
    window_lines: int = 128
    learning_rate: float = 5e-3
    val_share: float = 0.15
    loss: str = "rmse"
    log_inputs: tuple[int, ...] = field(default_factory=tuple)
    optimiser: str = "adam"
    momentum: float = 0.0

    def __post_init__(self) -> None:
        if self.loss not in ("rmse", "mse"):
            raise ValueError(f"loss = {self.loss!r} is unknown: allowed rmse, mse")
        if self.optimiser not in ("adam", "sgd"):
            raise ValueError(f"optimiser = {self.optimiser!r} is unknown: allowed adam, sgd")
        if not 0.0 <= self.momentum < 1.0:
            raise ValueError(f"momentum = {self.momentum!r} is out of range: allowed [0, 1)")
        if not 0.0 < self.val_share < 1.0:
            raise ValueError(f"val_share = {self.val_share!r} is out of range: allowed (0, 1)")
        for name in ("max_epochs", "patience", "batch_size", "window_lines"):
            if getattr(self, name) < 1:
                raise ValueError(f"{name} = {getattr(self, name)!r} is out of range: allowed >= 1")

    def to_dict(self) -> dict:
        d = asdict(self)
        d["log_inputs"] = list(self.log_inputs)
        # left out at their defaults, so that checkpoints made before they existed keep their keys
        for name, default in (("optimiser", "adam"), ("momentum", 0.0)):
            if d[name] == default:
                del d[name]
        return d


@dataclass(frozen=True)
class Scaler:
    """Standardisation ``(g(x) - mean) / std`` per column, ``g = log`` on ``log_columns``.

    Parameters
    ----------
    mean, std : ndarray, shape (n_columns,)
    log_columns : tuple of int
    """

    mean: np.ndarray
    std: np.ndarray
    log_columns: tuple[int, ...] = ()

    @classmethod
    def fit(cls, arrays: Sequence[np.ndarray], log_columns: Sequence[int] = ()) -> Scaler:
        """Statistics of the rows of ``arrays`` (each (N_i, n_columns)), NaNs ignored; a
        constant column gets ``std = 1``."""
        x = _log(np.concatenate(arrays), tuple(log_columns))
        mean = np.nanmean(x, axis=0)
        std = np.nanstd(x, axis=0)
        return cls(mean, np.where(std > 0, std, 1.0), tuple(log_columns))

    def transform(self, x: np.ndarray) -> np.ndarray:
        """Scaled copy of ``x`` (N, n_columns), float32 (computed in float64, in place)."""
        if self.log_columns:
            z = _log(x, self.log_columns) - self.mean
        else:
            z = np.subtract(x, self.mean, dtype=np.float64)
        z /= self.std
        return z.astype(np.float32)

    def inverse(self, z: np.ndarray) -> np.ndarray:
        """Undo :meth:`transform` (float64)."""
        x = np.asarray(z, dtype=np.float64) * self.std + self.mean
        if self.log_columns:
            x[:, list(self.log_columns)] = np.exp(x[:, list(self.log_columns)])
        return x


def _log(x: np.ndarray, columns: tuple[int, ...]) -> np.ndarray:
    x = np.array(x, dtype=np.float64)
    if columns:
        x[:, list(columns)] = np.log(x[:, list(columns)])
    return x


@dataclass(frozen=True, eq=False)
class Trained:
    """A trained model with its scalers and training record.

    Parameters
    ----------
    model : SequenceModel or BPNetwork
        In evaluation mode, best validation weights.
    x_scaler, y_scaler : Scaler
    train_config : TrainConfig
    history : dict
        ``{"train": [...], "val": [...]}`` losses per epoch (scaled targets).
    best_epoch : int
        Epoch (from 1) of the kept weights.
    train_seconds : float
        Wall time of the training run (as recorded when the checkpoint was made).
    path : Path
        The checkpoint.
    """

    model: SequenceModel | BPNetwork
    x_scaler: Scaler
    y_scaler: Scaler
    train_config: TrainConfig
    history: dict
    best_epoch: int
    train_seconds: float
    path: Path

    @property
    def converged(self) -> bool:
        """Whether early stopping, not the epoch cap, ended the training: it stopped before
        ``max_epochs`` (the validation loss had not improved for ``patience`` epochs), that is,
        the best epoch lies more than ``patience`` epochs below ``max_epochs``."""
        return len(self.history["train"]) < self.train_config.max_epochs

    def predict(self, x: np.ndarray) -> np.ndarray:
        """Outputs for one program, shape (N, n_outputs), from inputs (N, n_inputs).

        A sequence model runs overlapping windows of ``window_lines`` in one batch and keeps the
        middle half of each (see the module docstring); a per-row network (an MLP, the BP
        network) runs all rows in one pass."""
        z = torch.from_numpy(self.x_scaler.transform(x))
        n, w = len(z), self.train_config.window_lines
        with torch.no_grad(), one_thread():
            per_row = isinstance(self.model, BPNetwork) or self.model.config.kind == "mlp"
            if n <= w or per_row:  # no windows
                out = self.model(z[None])[0].numpy()
            else:
                core = max(w // 2, 1)
                a = np.arange(0, n, core)
                s = np.clip(a - (w - core) // 2, 0, n - w)
                idx = s[:, None] + np.arange(w)[None, :]
                y = self.model(z[torch.from_numpy(idx)]).numpy()  # (windows, w, out)
                out = np.empty((n, y.shape[-1]), dtype=y.dtype)
                for i, (ai, si) in enumerate(zip(a, s, strict=True)):
                    b = min(ai + core, n)
                    out[ai:b] = y[i, ai - si : b - si]
        return self.y_scaler.inverse(out)


@contextmanager
def one_thread() -> Iterator[None]:
    """Run torch on one intra-op thread, and restore the count after.

    Training and prediction both do: the summation order, hence the rounding, of a reduction
    depends on the thread count, and on a loaded machine two threads of a small network wait for
    each other (a prediction took 2 s with two threads and 0.1 s with one under a load average of
    12 on two cores).
    """
    threads = torch.get_num_threads()
    torch.set_num_threads(1)
    try:
        yield
    finally:
        torch.set_num_threads(threads)


def data_hash(xs: Sequence[np.ndarray], ys: Sequence[np.ndarray]) -> str:
    """SHA-256 of the training data (shapes and bytes of every array, in order)."""
    return content_key(*(np.asarray(a, dtype=np.float64) for a in (*xs, *ys)))


def _split(n_programs: int, cfg: TrainConfig) -> tuple[np.ndarray, np.ndarray]:
    """Training and validation program indices (seeded permutation)."""
    if n_programs < 2:
        raise ValueError(f"need at least 2 programs (training and validation), got {n_programs}")
    order = np.random.default_rng([cfg.seed, 1]).permutation(n_programs)
    n_val = min(max(1, round(cfg.val_share * n_programs)), n_programs - 1)
    return np.sort(order[n_val:]), np.sort(order[:n_val])


def _windows(lengths: Sequence[int], w: int, rng: np.random.Generator | None) -> np.ndarray:
    """(program, start, valid) of windows covering every program, shape (B, 3); a random offset
    per program (none when ``rng`` is None). Programs shorter than ``w`` give one window,
    padded, and draw no offset."""
    if max(lengths) <= w:  # one window each (the BP network's chunks): no loop
        return np.stack([np.arange(len(lengths)), np.zeros(len(lengths), int), lengths], axis=1)
    out = []
    for p, n in enumerate(lengths):
        if n <= w:
            out.append((p, 0, n))
            continue
        offset = int(rng.integers(0, w)) if rng is not None else 0
        starts = np.arange(offset, n - w + 1, w)
        if offset > 0:
            starts = np.concatenate([[0], starts])
        if starts[-1] + w < n:
            starts = np.append(starts, n - w)
        out += [(p, int(s), w) for s in starts]
    return np.array(out)


class _Programs:
    """Programs stacked once into float32 rows, so that a batch of windows is one gather.

    Parameters
    ----------
    zx, zy : sequences of ndarray, shapes (N_i, n_inputs) and (N_i, n_outputs)
        Scaled programs.
    """

    def __init__(self, zx: Sequence[np.ndarray], zy: Sequence[np.ndarray]) -> None:
        self.x = np.concatenate(zx).astype(np.float32)
        self.y = np.concatenate(zy).astype(np.float32)
        self.lengths = [len(x) for x in zx]
        self.start = np.cumsum([0, *self.lengths])[:-1]

    def batch(self, windows: np.ndarray, w: int, *, out=None):
        """Stack ``windows`` (B, 3) of (program, start, valid) into (B, w, n) inputs, targets
        and a mask of valid, finite targets; rows past a window's valid length are zero.

        ``out``: float32 arrays (B, w, n_inputs) and (B, w, n_outputs) to write the inputs and
        targets into (by default, new ones)."""
        steps = np.arange(w)
        valid = steps < windows[:, 2:3]
        rows = np.where(valid, self.start[windows[:, 0:1]] + windows[:, 1:2] + steps, 0)
        x_out, y_out = out if out is not None else (None, None)
        x = np.take(self.x, rows, axis=0, out=x_out)  # copies
        y = np.take(self.y, rows, axis=0, out=y_out)
        x[~valid] = 0.0
        m = valid[..., None] & np.isfinite(y)
        y[~m] = 0.0
        return torch.from_numpy(x), torch.from_numpy(y), torch.from_numpy(m)


def _loss(pred: torch.Tensor, y: torch.Tensor, mask: torch.Tensor, kind: str) -> torch.Tensor:
    mse = ((pred - y) ** 2 * mask).sum() / mask.sum().clamp(min=1)
    return mse.sqrt() if kind == "rmse" else mse


def _autograd_step(model, optimiser, kind: str, x, y, mask) -> torch.Tensor:
    """One optimiser step on a batch by autograd; the batch's loss, before the step."""
    loss = _loss(model(x), y, mask, kind)
    optimiser.zero_grad()
    loss.backward()
    optimiser.step()
    return loss.detach()


class _NaNWeights(Exception):
    """A weight became NaN before any epoch had a finite validation loss (:func:`_train`)."""


#: Batches whose windows :meth:`_AutogradRun.epoch` gathers at once (the gather is a fixed cost
#: per call, as large as a small network's step).
_BATCHES_PER_GATHER = 64


class _SGD:
    """Stochastic gradient descent with momentum: :func:`torch.optim.sgd.sgd`, the update that
    ``torch.optim.SGD(params, lr=lr, momentum=momentum, foreach=True).step()`` runs, bit for
    bit, called without the optimiser object's per-step bookkeeping.

    Parameters
    ----------
    params : iterable of torch.Tensor
    lr : float
    momentum : float
    """

    def __init__(self, params, lr: float, momentum: float) -> None:
        self.params = list(params)
        self.lr, self.momentum = lr, momentum
        # one buffer per parameter, made on the first step (torch.optim.SGD's state); none
        # without momentum, as torch.optim.SGD passes none
        self.buffers: list[torch.Tensor | None] = [None] * len(self.params) if momentum else []

    def zero_grad(self) -> None:
        for p in self.params:
            p.grad = None

    @torch.no_grad()
    def step(self) -> None:
        sgd(self.params, [p.grad for p in self.params], self.buffers, weight_decay=0.0,
            momentum=self.momentum, lr=self.lr, dampening=0.0, nesterov=False, maximize=False,
            foreach=True, has_sparse_grad=False)  # fmt: skip


class _AutogradRun:
    """Epochs by autograd and a :mod:`torch.optim` optimiser, validation by the torch model."""

    def __init__(self, model, cfg: TrainConfig, programs: _Programs, validation: _Programs):
        self.model, self.cfg, self.programs = model, cfg, programs
        w = cfg.window_lines
        self.validation = validation.batch(_windows(validation.lengths, w, None), w)
        # a BP network maps rows: a batch of windows runs as one matrix of rows
        self.rows = isinstance(model, BPNetwork)
        if self.rows:
            x, y, mask = (t.flatten(0, 1) for t in self.validation)
            self.validation = x, y, mask.to(torch.float32)
        if cfg.optimiser == "sgd":
            self.optimiser = _SGD(model.parameters(), cfg.learning_rate, cfg.momentum)
        else:  # foreach: bit for bit the per-tensor loop (the CPU default), and faster
            self.optimiser = torch.optim.Adam(model.parameters(), cfg.learning_rate, foreach=True)

    def epoch(self, windows: np.ndarray, *, stop_if_nan: bool = False) -> float:
        """Steps on ``windows`` in batches of ``batch_size``; the mean of the batch losses,
        weighted by their windows.

        With ``stop_if_nan``, a batch loss that is not finite is followed by a look at the
        weights: if one is NaN, :class:`_NaNWeights` is raised (see :func:`_train`).
        """
        self.model.train()
        total, count, cfg = 0.0, 0, self.cfg
        chunk = cfg.batch_size * _BATCHES_PER_GATHER
        for c in range(0, len(windows), chunk):  # one gather for many batches
            xs, ys, ms = self.programs.batch(windows[c : c + chunk], cfg.window_lines)
            if self.rows:
                ms = ms.to(torch.float32)  # the bool mask's products, without a cast per step
            for b in range(0, len(xs), cfg.batch_size):
                bx, by, bm = (t[b : b + cfg.batch_size] for t in (xs, ys, ms))
                n_windows = len(bx)
                if self.rows:
                    bx, by, bm = (t.flatten(0, 1) for t in (bx, by, bm))
                loss = float(_autograd_step(self.model, self.optimiser, cfg.loss, bx, by, bm))
                if stop_if_nan and not math.isfinite(loss) and self.nan_weights():
                    raise _NaNWeights
                total += loss * n_windows
                count += n_windows
        self.model.eval()
        return total / count

    def nan_weights(self) -> bool:
        """Whether a weight is NaN."""
        return any(bool(torch.isnan(p).any()) for p in self.model.parameters())

    def validate(self) -> float:
        with torch.no_grad():
            x, y, mask = self.validation
            return float(_loss(self.model(x), y, mask, self.cfg.loss))

    def state(self):
        return copy.deepcopy(self.model.state_dict())

    def load(self, state) -> None:
        self.model.load_state_dict(state)


def fit(
    model_config: ModelConfig | BPConfig,
    train_config: TrainConfig,
    xs: Sequence[np.ndarray],
    ys: Sequence[np.ndarray],
    *,
    name: str = "model",
    cache: bool = True,
    progress: bool = True,
    validation: tuple[Sequence[np.ndarray], Sequence[np.ndarray]] | None = None,
    init: Trained | None = None,
) -> Trained:
    """Train ``model_config`` on programs ``xs``/``ys``, or load the cached checkpoint.

    Parameters
    ----------
    model_config : ModelConfig or BPConfig
    train_config : TrainConfig
    xs, ys : sequences of ndarray, shapes (N_i, n_inputs) and (N_i, n_outputs)
        One entry per program.
    name : str
        Prefix of the checkpoint file.
    cache : bool
        Load a checkpoint with the same data and configs if present; save the result.
    progress : bool
        Show a tqdm bar over epochs, from 5 s into the training on, unless the environment sets
        ``TQDM_DISABLE=1`` (for headless runs).
    validation : (xs, ys), optional
        Programs to validate on, given explicitly (e.g. half of a pocket, Sun et al. 2022,
        Table 2); then every program of ``xs``/``ys`` trains and ``val_share`` is not used.
    init : Trained, optional
        Fine-tune: start from these weights and keep their scalers (the inputs of a trained
        network keep the scaling it learned with); ``model_config`` must be its config.

    Returns
    -------
    Trained
    """
    if len(xs) != len(ys):
        raise ValueError(f"xs and ys differ in length: {len(xs)} and {len(ys)}")
    if init is not None and init.model.config != model_config:
        raise ValueError(
            f"init has model config {init.model.config!r}, not model_config = {model_config!r}"
        )
    val_key = data_hash(*validation) if validation is not None else None
    path = checkpoint_path(
        name, model_config, train_config, data_hash(xs, ys), validation_key=val_key, init=init
    )
    diverged = path.with_suffix(".diverged")  # the message of a training that diverged
    if cache and diverged.exists():
        raise TrainingDivergedError(diverged.read_text(encoding="utf-8"))
    if cache and path.exists():
        return load_checkpoint(path)

    try:
        if validation is not None:  # the given programs validate, all others train
            n = len(xs)
            xs, ys = [*xs, *validation[0]], [*ys, *validation[1]]
            split = (np.arange(n), np.arange(n, len(xs)))
        else:
            split = _split(len(xs), train_config)
        # dropout masks come from torch's global generator: seed it inside a forked state, so
        # training repeats bit for bit and the caller's random state is left as it was
        with torch.random.fork_rng(devices=[]), deterministic():
            torch.manual_seed(train_config.seed)
            trained = _train(model_config, train_config, xs, ys, path, progress, split, init)
    except TrainingDivergedError as error:
        if cache:
            atomic_write_text(diverged, str(error))
        raise
    if cache:
        save_checkpoint(trained)
    return trained


def checkpoint_path(
    name: str,
    model_config: ModelConfig | BPConfig,
    train_config: TrainConfig,
    data_key: str,
    *,
    validation_key: str | None = None,
    init: Trained | None = None,
    **extra,
) -> Path:
    """The checkpoint of a training (see the module docstring): ``name`` and a SHA-256 of the
    data's :func:`data_hash` (``data_key``, ``validation_key``), the configs, the CPU kernels,
    ``init``'s checkpoint and ``extra`` (keys a variant of the loop adds, so that its networks
    and :func:`fit`'s never share a file)."""
    key = {"data": data_key, "validation": validation_key, "model": model_config.to_dict(),
           "train": train_config.to_dict(),
           "cpu": torch.backends.cpu.get_cpu_capability(),
           "pins": {name: os.environ.get(name, "") for name in KERNEL_PINS}, **extra}  # fmt: skip
    if init is not None:  # only then, so that earlier keys stay valid
        key["init"] = init.path.name
    return cache_path("models", name, content_key(key), ".pt")


@contextmanager
def deterministic() -> Iterator[None]:
    """Deterministic algorithms, one torch thread and one BLAS thread (see the module
    docstring, "Determinism"); restored after."""
    before = torch.are_deterministic_algorithms_enabled()
    torch.use_deterministic_algorithms(True)
    try:
        with one_thread(), threadpool_limits(1, user_api="blas"):
            yield
    finally:
        torch.use_deterministic_algorithms(before)


def scaled_programs(cfg: TrainConfig, xs, ys, split, init: Trained | None = None):
    """The scalers (fitted on the training programs of ``split``, or ``init``'s) and the
    scaled training and validation programs (:class:`_Programs`)."""
    train_idx, val_idx = split
    if init is not None:
        x_scaler, y_scaler = init.x_scaler, init.y_scaler
    else:
        x_scaler = Scaler.fit([xs[i] for i in train_idx], cfg.log_inputs)
        y_scaler = Scaler.fit([ys[i] for i in train_idx])
    zx = [x_scaler.transform(x) for x in xs]
    zy = [y_scaler.transform(y) for y in ys]
    return (
        x_scaler, y_scaler,
        _Programs([zx[i] for i in train_idx], [zy[i] for i in train_idx]),
        _Programs([zx[i] for i in val_idx], [zy[i] for i in val_idx]),
    )  # fmt: skip


def _train(
    model_config, cfg: TrainConfig, xs, ys, path: Path, progress: bool, split, init=None
) -> Trained:
    t0 = time.perf_counter()
    x_scaler, y_scaler, programs, validation = scaled_programs(cfg, xs, ys, split, init)
    w = cfg.window_lines
    generator = torch.Generator().manual_seed(cfg.seed)
    rng = np.random.default_rng([cfg.seed, 2])
    if isinstance(model_config, BPConfig):
        model = build_bp(model_config, generator=generator)
    else:
        model = build(model_config, generator=generator)
    if init is not None:
        model.load_state_dict(init.model.state_dict())
    run = _AutogradRun(model, cfg, programs, validation)
    history: dict[str, list[float]] = {"train": [], "val": []}
    best, best_state, best_epoch, stale = math.inf, None, 0, 0
    # shown after 5 s only, so that short runs leave no text in executed notebooks; ``disable``
    # is passed only to hide it, so that TQDM_DISABLE=1 in the environment hides it too
    bar = tqdm(
        range(1, cfg.max_epochs + 1),
        desc=path.stem,
        leave=False,
        mininterval=5.0,
        delay=5.0,
        **({} if progress else {"disable": True}),
    )
    for epoch in bar:
        windows = _windows(programs.lengths, w, rng)
        # a NaN weight stays NaN (every update adds to it) and makes every output NaN, so no
        # later epoch can have a finite validation loss: a run that had none yet has diverged,
        # and stops there (a run that had one goes on, so that its history is what it was)
        try:
            train_loss = run.epoch(windows[rng.permutation(len(windows))],
                                   stop_if_nan=best_state is None)  # fmt: skip
        except _NaNWeights:
            break
        val = run.validate()
        history["train"].append(train_loss)
        history["val"].append(val)
        if not bar.disable:  # formatting costs 40 us, as much as a small epoch's step
            bar.set_postfix(train=f"{train_loss:.4f}", val=f"{val:.4f}", refresh=False)
        if val < best:
            best, best_state, best_epoch, stale = val, run.state(), epoch, 0
        else:
            stale += 1
            if stale >= cfg.patience:
                break
    bar.close()
    if best_state is None:
        raise TrainingDivergedError(
            f"{path.stem}: the validation loss was never finite (the training diverged); "
            f"learning_rate = {cfg.learning_rate!r} may be too large"
        )
    run.load(best_state)
    model.eval()
    return Trained(
        model, x_scaler, y_scaler, cfg, history, best_epoch, time.perf_counter() - t0, path
    )


def _scaler_dict(s: Scaler) -> dict:
    return {"mean": torch.from_numpy(s.mean), "std": torch.from_numpy(s.std),
            "log_columns": list(s.log_columns)}  # fmt: skip


def _scaler_of(d: dict) -> Scaler:
    return Scaler(d["mean"].numpy(), d["std"].numpy(), tuple(d["log_columns"]))


def save_checkpoint(trained: Trained) -> Path:
    """Write ``trained`` to its path atomically (temporary file in the folder, then rename)."""
    path = trained.path
    payload = {
        "model_type": type(trained.model.config).__name__,
        "model_config": trained.model.config.to_dict(),
        "train_config": trained.train_config.to_dict(),
        "state_dict": trained.model.state_dict(),
        "x_scaler": _scaler_dict(trained.x_scaler),
        "y_scaler": _scaler_dict(trained.y_scaler),
        "history": trained.history,
        "best_epoch": trained.best_epoch,
        "train_seconds": trained.train_seconds,
    }
    return atomic_write(path, lambda tmp: torch.save(payload, tmp))


def load_checkpoint(path: str | os.PathLike) -> Trained:
    """Read a checkpoint written by :func:`save_checkpoint` (``weights_only=True``)."""
    path = Path(path)
    d = torch.load(path, map_location="cpu", weights_only=True)
    mc = dict(d["model_config"])
    if d.get("model_type") == "BPConfig":
        model: SequenceModel | BPNetwork = BPNetwork(BPConfig(**mc))
    else:
        mc["mlp_widths"] = tuple(mc.get("mlp_widths", ()))
        model = SequenceModel(ModelConfig(**mc))
    tc = dict(d["train_config"])
    tc["log_inputs"] = tuple(tc["log_inputs"])
    model.load_state_dict(d["state_dict"])
    model.eval()
    return Trained(
        model, _scaler_of(d["x_scaler"]), _scaler_of(d["y_scaler"]), TrainConfig(**tc),
        d["history"], int(d["best_epoch"]), float(d["train_seconds"]), path,
    )  # fmt: skip
