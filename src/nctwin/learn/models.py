"""Small torch sequence models, each described by a frozen config stored with its checkpoint.

One module, one config (after nanoGPT): :class:`ModelConfig` says which network and how large;
:func:`build` makes it. All models map a sequence of per-G-line features, shape
(batch, lines, n_inputs), to per-G-line outputs, shape (batch, lines, n_outputs).

* ``"bilstm"`` -- Chien, Sencer & Ward (2023, Sec. 4.1, Fig. 4): one bidirectional LSTM layer
  (tanh, ``hidden`` units per direction) and a fully connected linear output. The backward
  direction reads the G-lines that follow, as the NC kernel's look-ahead does.
* ``"lstm"`` -- the same, forward direction only (no look-ahead): an ablation; with
  ``lstm_layers`` > 1 a stack of LSTM layers with ``dropout`` between them (Denkena et al. 2020,
  Sec. 2.3: three layers of 20 cells).
* ``"mlp"`` -- a per-line multilayer perceptron (tanh) that sees one G-line's features only: an
  ablation without any sequence context.

:class:`BPNetwork` (config :class:`BPConfig`, made by :func:`build_bp`) is the BP network of
Zhang et al. (2023): one sample per row, ReLU hidden layers with dropout.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import torch
from torch import nn

__all__ = ["KINDS", "BPConfig", "BPNetwork", "ModelConfig", "SequenceModel", "build", "build_bp"]

#: Model kinds :func:`build` knows.
KINDS = ("bilstm", "lstm", "mlp")


@dataclass(frozen=True)
class ModelConfig:
    """Architecture of a sequence model.

    Parameters
    ----------
    kind : {"bilstm", "lstm", "mlp"}
    n_inputs : int
        Features per G-line.
    n_outputs : int
        Outputs per G-line.
    hidden : int
        LSTM units per direction, or width of each MLP hidden layer.
    mlp_layers : int
        Hidden layers of the MLP (ignored by the LSTMs).
    mlp_widths : tuple of int
        Widths of the MLP's hidden layers, one per layer (e.g. ``(5, 10)``, Sun et al. 2022);
        when given, they replace ``hidden`` and ``mlp_layers`` for the MLP.
    lstm_layers : int
        Stacked LSTM layers (ignored by the MLP); default 1.
    dropout : float
        Probability of dropping an output of every LSTM layer but the last during training
        (PyTorch's ``nn.LSTM(dropout=...)``), in [0, 1); needs ``lstm_layers`` > 1 to act.
        Default 0.
    """

    kind: str = "bilstm"
    n_inputs: int = 5
    n_outputs: int = 1
    hidden: int = 10
    mlp_layers: int = 2
    mlp_widths: tuple[int, ...] = ()
    lstm_layers: int = 1
    dropout: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "mlp_widths", tuple(int(w) for w in self.mlp_widths))
        if any(w < 1 for w in self.mlp_widths):
            raise ValueError(f"mlp_widths = {self.mlp_widths!r} is out of range: allowed >= 1")
        if self.kind not in KINDS:
            raise ValueError(f"kind = {self.kind!r} is unknown: allowed {', '.join(KINDS)}")
        for name in ("n_inputs", "n_outputs", "hidden", "mlp_layers", "lstm_layers"):
            if getattr(self, name) < 1:
                raise ValueError(f"{name} = {getattr(self, name)!r} is out of range: allowed >= 1")
        if not 0.0 <= self.dropout < 1.0:
            raise ValueError(f"dropout = {self.dropout!r} is out of range: allowed [0, 1)")

    def to_dict(self) -> dict:
        """Plain dict (what the checkpoint stores).

        ``lstm_layers`` and ``dropout`` are left out at their defaults, so that configs made
        before they existed keep their checkpoint keys."""
        d = asdict(self)
        d["mlp_widths"] = list(self.mlp_widths)
        for name, default in (("lstm_layers", 1), ("dropout", 0.0)):
            if d[name] == default:
                del d[name]
        return d


class SequenceModel(nn.Module):
    """A per-G-line regressor: LSTM layer (or MLP) and a linear output.

    ``forward(x)`` takes x of shape (batch, lines, n_inputs) and returns (batch, lines,
    n_outputs).
    """

    def __init__(self, config: ModelConfig) -> None:
        super().__init__()
        self.config = config
        c = config
        if c.kind == "mlp":
            layers: list[nn.Module] = []
            width = c.n_inputs
            for size in c.mlp_widths or (c.hidden,) * c.mlp_layers:
                layers += [nn.Linear(width, size), nn.Tanh()]
                width = size
            self.body: nn.Module = nn.Sequential(*layers)
            self.head = nn.Linear(width, c.n_outputs)
        else:
            bidirectional = c.kind == "bilstm"
            self.body = nn.LSTM(
                c.n_inputs,
                c.hidden,
                num_layers=c.lstm_layers,
                batch_first=True,
                bidirectional=bidirectional,
                dropout=c.dropout,
            )
            self.head = nn.Linear(c.hidden * (2 if bidirectional else 1), c.n_outputs)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        h = self.body(x)
        if isinstance(h, tuple):  # LSTM: (output, (h_n, c_n))
            h = h[0]
        return self.head(h)


def build(config: ModelConfig, *, generator: torch.Generator | None = None) -> SequenceModel:
    """Make the model of ``config`` with weights drawn from ``generator`` (reproducible).

    The default initialisations of :mod:`torch.nn` draw from the global generator; the weights
    are redrawn here with the same distributions (uniform in ``(-1/sqrt(fan), 1/sqrt(fan))``, the
    PyTorch default for LSTM and Linear layers) from the given generator instead.
    """
    model = SequenceModel(config)
    with torch.no_grad():
        for name, p in model.named_parameters():
            if isinstance(model.body, nn.LSTM) and name.startswith("body."):
                fan = config.hidden
            else:
                fan = p.shape[-1] if p.ndim > 1 else _fan_in(model, name)
            bound = fan**-0.5
            p.copy_(torch.empty_like(p).uniform_(-bound, bound, generator=generator))
    return model


def _fan_in(model: nn.Module, bias_name: str) -> int:
    """Fan-in of the layer a bias belongs to (the width of its weight's last axis)."""
    weight = dict(model.named_parameters())[bias_name.rsplit(".", 1)[0] + ".weight"]
    return int(weight.shape[-1])


# ----------------------------------------------------------------------------------------------
# Zhang et al. (2023): the BP network for tool-path step error


@dataclass(frozen=True)
class BPConfig:
    r"""The BP network of Zhang et al. (2023, Fig. 2-3, Sec. "Network parameter determination").

    Fully connected: ``n_inputs`` -> ReLU layers of ``hidden`` widths (paper: 28 and 20, sized
    by eq. 8), each followed by dropout -> linear output. One sample per row: the network maps
    (..., n_inputs) to (..., n_outputs), so it also runs on the (batch, lines, n_inputs) windows
    of :mod:`nctwin.learn.train`.

    Parameters
    ----------
    n_inputs : int
        Sample width (Table 1).
    hidden : tuple of int
        Hidden layer widths.
    n_outputs : int
    dropout : float
        Probability of *dropping* a hidden unit during training, in [0, 1) (PyTorch's
        convention; the paper's eq. 13 names the keep probability :math:`p`, but its Table 2
        rises at large :math:`p`, as dropping, not keeping, does). 0 switches dropout off.
    weight_init : {"normal", "uniform"}
        ``"normal"``: weights :math:`\sim N(0, \text{weight\_std}^2)` (eq. 10; paper: N(0, 1));
        ``"uniform"``: PyTorch's default, :math:`U(-1/\sqrt{\text{fan}_\text{in}},
        1/\sqrt{\text{fan}_\text{in}})`. Biases are always the latter (eq. 11 gives no bounds).
    weight_std : float
        Standard deviation of ``"normal"`` weights, > 0.
    """

    n_inputs: int = 325
    hidden: tuple[int, ...] = (28, 20)
    n_outputs: int = 1
    dropout: float = 0.5
    weight_init: str = "normal"
    weight_std: float = 1.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "hidden", tuple(int(h) for h in self.hidden))
        for name in ("n_inputs", "n_outputs"):
            if getattr(self, name) < 1:
                raise ValueError(f"{name} = {getattr(self, name)!r} is out of range: allowed >= 1")
        if not self.hidden or any(h < 1 for h in self.hidden):
            raise ValueError(f"hidden = {self.hidden!r} is out of range: allowed widths >= 1")
        if not 0.0 <= self.dropout < 1.0:
            raise ValueError(f"dropout = {self.dropout!r} is out of range: allowed [0, 1)")
        if self.weight_init not in ("normal", "uniform"):
            raise ValueError(
                f"weight_init = {self.weight_init!r} is unknown: allowed normal, uniform"
            )
        if not self.weight_std > 0:
            raise ValueError(f"weight_std = {self.weight_std!r} is out of range: allowed > 0")

    def to_dict(self) -> dict:
        """Plain dict (what the checkpoint stores)."""
        d = asdict(self)
        d["hidden"] = list(self.hidden)
        return d


class BPNetwork(nn.Module):
    """The network of :class:`BPConfig`; ``forward`` maps (..., n_inputs) to (..., n_outputs)."""

    def __init__(self, config: BPConfig) -> None:
        super().__init__()
        self.config = config
        layers: list[nn.Module] = []
        width = config.n_inputs
        for size in config.hidden:
            layers += [nn.Linear(width, size), nn.ReLU(), nn.Dropout(config.dropout)]
            width = size
        layers.append(nn.Linear(width, config.n_outputs))
        self.layers = nn.Sequential(*layers)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return self.layers(x)


def build_bp(config: BPConfig, *, generator: torch.Generator | None = None) -> BPNetwork:
    """Make the network of ``config`` with weights drawn from ``generator`` (reproducible)."""
    model = BPNetwork(config)
    with torch.no_grad():
        for layer in model.layers:
            if not isinstance(layer, nn.Linear):
                continue
            bound = layer.in_features**-0.5
            if config.weight_init == "normal":
                layer.weight.normal_(0.0, config.weight_std, generator=generator)
            else:
                layer.weight.uniform_(-bound, bound, generator=generator)
            layer.bias.uniform_(-bound, bound, generator=generator)
    return model
