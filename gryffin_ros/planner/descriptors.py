"""Dynamic descriptors (Gryffin's `auto_desc_gen`): for a categorical parameter with several descriptors, learn a
transform gen = softsign(d W + b) (W starts as the identity) whose columns correlate with the target (the merits, or
the failure labels for the feasibility model) and not with each other; keep the columns whose |correlation| exceeds
r_min = 1/sqrt(N - 2), the significance level of a Pearson correlation over N observations.

Loss: mean_c sin^2(pi/2 (1 - |r_c|)) + mean_{c<c'} sin^2(pi/2 |r_cc'|) + 0.01 mean|W|, by Adam.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import torch

STEPS = 300
LEARNING_RATE = 0.02
WEIGHT_PENALTY = 0.01
MIN_OBSERVATIONS = 4


@dataclass
class LearnedDescriptors:
    """The transformed descriptor table (options, kept columns) rescaled to [0, 1], and what was learned."""

    table: np.ndarray
    correlations: np.ndarray  # (m,) correlation of each generated column with the target
    kept: np.ndarray  # (m,) bool
    relevance: np.ndarray  # (m_original,) share of each original descriptor in the kept columns, sums to 1


def _pearson(a: torch.Tensor, b: torch.Tensor) -> torch.Tensor:
    """Column-wise correlations: a (N, p), b (N, q) -> (p, q)."""
    a = a - a.mean(0)
    b = b - b.mean(0)
    norm = torch.sqrt((a ** 2).sum(0))[:, None] * torch.sqrt((b ** 2).sum(0))[None, :]
    return (a.T @ b) / norm.clamp_min(1e-12)


def learn_descriptors(descriptors: np.ndarray, options: np.ndarray, target: np.ndarray) -> LearnedDescriptors | None:
    """descriptors (K, m) in [0, 1], options (N,) observed option indices, target (N,) -> the learned table, or None
    when the data cannot support it (fewer than 4 observations, a constant target or constant descriptors)."""
    n, m = len(options), descriptors.shape[1]
    if n < MIN_OBSERVATIONS or np.ptp(target) == 0 or m < 2:
        return None
    d_all = torch.as_tensor(descriptors, dtype=torch.float64)
    x = d_all[torch.as_tensor(options, dtype=torch.long)]
    if float(x.std(0).max()) == 0.0:
        return None
    y = torch.as_tensor(target, dtype=torch.float64)[:, None]
    weights = torch.eye(m, dtype=torch.float64, requires_grad=True)
    bias = torch.zeros(m, dtype=torch.float64, requires_grad=True)
    adam = torch.optim.Adam([weights, bias], lr=LEARNING_RATE)
    pairs = torch.triu_indices(m, m, offset=1)

    def transform(d: torch.Tensor) -> torch.Tensor:
        z = d @ weights + bias
        return z / (1.0 + z.abs())

    for _ in range(STEPS):
        adam.zero_grad()
        gen = transform(x)
        with_target = _pearson(gen, y)[:, 0]
        among = _pearson(gen, gen)[pairs[0], pairs[1]]
        loss = (torch.sin(0.5 * math.pi * (1.0 - with_target.abs())) ** 2).mean() \
            + (torch.sin(0.5 * math.pi * among.abs()) ** 2).mean() + WEIGHT_PENALTY * weights.abs().mean()
        loss.backward()
        adam.step()
    with torch.no_grad():
        gen = transform(x).numpy()
        correlations = np.nan_to_num(_pearson(transform(x), y)[:, 0].numpy())
        table = transform(d_all).numpy()
        z = (x @ weights + bias).numpy()
    kept = np.abs(correlations) > 1.0 / math.sqrt(n - 2)
    if not kept.any():
        return None
    # relevance: how strongly a least-squares fit of the target on the kept columns responds to each original
    # descriptor (mean |d fit / d descriptor| over the observations, times the descriptor's spread)
    design = np.column_stack([gen[:, kept], np.ones(n)])
    beta = np.linalg.lstsq(design, target, rcond=None)[0][:-1]
    slope = 1.0 / (1.0 + np.abs(z[:, kept])) ** 2  # softsign'
    sensitivity = np.abs((slope * beta) @ weights.detach().numpy()[:, kept].T).mean(0) * x.numpy().std(0)
    table = table[:, kept]
    low, high = table.min(0), table.max(0)
    table = (table - low) / np.where(high > low, high - low, 1.0)
    total = sensitivity.sum()
    return LearnedDescriptors(table, correlations, kept, sensitivity / total if total > 0 else sensitivity)
