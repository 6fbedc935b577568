"""Dynamic descriptors (Gryffin's `auto_desc_gen`): for a categorical parameter with several descriptors, learn a
transform gen = softsign(d W + b) (W starts as the identity) whose columns correlate with the target (the merits, or
the failure labels for the feasibility model) and not with each other; keep the columns whose |correlation| exceeds
r_min = 1/sqrt(N - 2), the significance level of a Pearson correlation over N observations.

Loss: mean_c sin^2(pi/2 (1 - |r_c|)) + mean_{c<c'} sin^2(pi/2 |r_cc'|) + 0.01 mean|W|, by Adam.

Descriptors that are constant over the observed options say nothing about the target and are left out of the
transform (their generated column would be constant, its correlation 0/0, and its gradient would turn every weight
into NaN). Several parameters are learned in one optimization (`learn_many`): their losses are summed but share no
weight, and Adam updates every weight on its own, so each result is the one it would get alone.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import torch

STEPS = 300
LEARNING_RATE = 0.02
BETA1, BETA2, EPSILON = 0.9, 0.999, 1e-8  # Adam's defaults
WEIGHT_PENALTY = 0.01
MIN_OBSERVATIONS = 4


@dataclass
class LearnedDescriptors:
    """The transformed descriptor table (options, kept columns) rescaled to [0, 1], and what was learned."""

    table: np.ndarray
    correlations: np.ndarray  # (m,) correlation of generated column c (from descriptor c) with the target
    kept: np.ndarray  # (m,) bool; False for descriptors constant over the observed options
    relevance: np.ndarray  # (m,) share of each original descriptor in the kept columns, sums to 1


def _pearson(a: torch.Tensor, b: torch.Tensor, a_pad: torch.Tensor | float = 0.0, b_pad: torch.Tensor | float = 0.0
             ) -> torch.Tensor:
    """Column-wise correlations per problem: a (B, N, p), b (B, N, q) -> (B, p, q). `a_pad` (B, p) and `b_pad` are 1
    for padding columns (constant, so zero after centring): their norm is taken as 1, so they get correlation 0 and
    finite gradients (sqrt at 0 would give infinite ones, and NaN after the loss masks them out)."""
    a = a - a.mean(1, keepdim=True)
    b = b - b.mean(1, keepdim=True)
    norm_a = torch.sqrt((a ** 2).sum(1) + a_pad)
    norm_b = torch.sqrt((b ** 2).sum(1) + b_pad)
    return (a.transpose(1, 2) @ b) / (norm_a[:, :, None] * norm_b[:, None, :]).clamp_min(1e-12)


def learn_descriptors(descriptors: np.ndarray, options: np.ndarray, target: np.ndarray) -> LearnedDescriptors | None:
    """descriptors (K, m) in [0, 1], options (N,) observed option indices, target (N,) -> the learned table, or None
    when the data cannot support it (fewer than 4 observations, a constant target, fewer than two descriptors, or
    every descriptor constant over the observed options)."""
    return learn_many([(descriptors, options)], target)[0]


def learn_many(problems: Sequence[tuple[np.ndarray, np.ndarray]], target: np.ndarray
               ) -> list[LearnedDescriptors | None]:
    """learn_descriptors for several (descriptors, options) pairs against one target, in one batched optimization."""
    target = np.asarray(target, dtype=float)
    n = len(target)
    results: list[LearnedDescriptors | None] = [None] * len(problems)
    if n < MIN_OBSERVATIONS or np.ptp(target) == 0:
        return results
    observed = [descriptors[np.asarray(options, dtype=int)] for descriptors, options in problems]  # (N, m) each
    informative = {}  # problem -> indices of descriptors that vary over its observed options
    for i, (descriptors, _) in enumerate(problems):
        if descriptors.shape[1] >= 2:
            varying = np.flatnonzero(np.ptp(observed[i], axis=0) > 0)
            if varying.size:
                informative[i] = varying
    if not informative:
        return results
    order = list(informative)
    B, M = len(order), max(len(v) for v in informative.values())
    x = torch.zeros((B, n, M), dtype=torch.float64)
    mask = torch.zeros((B, M), dtype=torch.float64)
    for j, i in enumerate(order):
        cols = informative[i]
        x[j, :, :len(cols)] = torch.as_tensor(observed[i][:, cols])
        mask[j, :len(cols)] = 1.0
    counts = mask.sum(1)
    square = mask[:, :, None] * mask[:, None, :]
    pairs = torch.triu(square, diagonal=1)
    pair_counts = pairs.sum((1, 2)).clamp_min(1.0)
    y = torch.as_tensor(target, dtype=torch.float64)[None, :, None].expand(B, n, 1)
    weights = (torch.eye(M, dtype=torch.float64)[None] * square).requires_grad_(True)
    bias = torch.zeros((B, M), dtype=torch.float64, requires_grad=True)
    moments = [(torch.zeros_like(p), torch.zeros_like(p)) for p in (weights, bias)]

    def transform(d: torch.Tensor) -> torch.Tensor:
        z = d @ weights + bias[:, None, :]
        return z / (1.0 + z.abs())

    for step in range(1, STEPS + 1):
        gen = transform(x)
        with_target = _pearson(gen, y, 1.0 - mask)[:, :, 0]
        among = _pearson(gen, gen, 1.0 - mask, 1.0 - mask)
        loss = ((torch.sin(0.5 * math.pi * (1.0 - with_target.abs())) ** 2 * mask).sum(1) / counts
                + (torch.sin(0.5 * math.pi * among.abs()) ** 2 * pairs).sum((1, 2)) / pair_counts
                + WEIGHT_PENALTY * (weights.abs() * square).sum((1, 2)) / counts ** 2)
        grads = torch.autograd.grad(loss.sum(), (weights, bias))
        with torch.no_grad():
            for parameter, grad, (m, v) in zip((weights, bias), grads, moments):
                m.mul_(BETA1).add_(grad, alpha=1 - BETA1)
                v.mul_(BETA2).addcmul_(grad, grad, value=1 - BETA2)
                denom = (v.sqrt() / math.sqrt(1 - BETA2 ** step)).add_(EPSILON)
                parameter.addcdiv_(m, denom, value=-LEARNING_RATE / (1 - BETA1 ** step))
    with torch.no_grad():
        correlations = torch.nan_to_num(_pearson(transform(x), y, 1.0 - mask)[:, :, 0]).numpy()
        W, b = weights.numpy(), bias.numpy()
    for j, i in enumerate(order):
        results[i] = _result(problems[i][0], observed[i], informative[i], W[j], b[j], correlations[j], target)
    return results


def _result(descriptors: np.ndarray, observed: np.ndarray, cols: np.ndarray, W: np.ndarray, b: np.ndarray,
            correlations: np.ndarray, target: np.ndarray) -> LearnedDescriptors | None:
    """One problem's learned table from its block of the batched weights (its first len(cols) rows and columns)."""
    n, k = len(target), len(cols)
    W, b, r = W[:k, :k], b[:k], correlations[:k]
    kept = np.abs(r) > 1.0 / math.sqrt(n - 2)
    if not kept.any():
        return None
    x = observed[:, cols]
    z = x @ W + b
    gen = z / (1.0 + np.abs(z))
    # relevance: how strongly a least-squares fit of the target on the kept columns responds to each original
    # descriptor (mean |d fit / d descriptor| over the observations, times the descriptor's spread)
    design = np.column_stack([gen[:, kept], np.ones(n)])
    beta = np.linalg.lstsq(design, target, rcond=None)[0][:-1]
    slope = 1.0 / (1.0 + np.abs(z[:, kept])) ** 2  # softsign'
    sensitivity = np.abs((slope * beta) @ W[:, kept].T).mean(0) * x.std(0)
    z_all = descriptors[:, cols] @ W + b
    table = (z_all / (1.0 + np.abs(z_all)))[:, kept]
    low, high = table.min(0), table.max(0)
    table = (table - low) / np.where(high > low, high - low, 1.0)
    m = descriptors.shape[1]
    full_r, full_kept, relevance = np.zeros(m), np.zeros(m, dtype=bool), np.zeros(m)
    full_r[cols], full_kept[cols] = r, kept
    total = sensitivity.sum()
    relevance[cols] = sensitivity / total if total > 0 else sensitivity
    return LearnedDescriptors(table, full_r, full_kept, relevance)
